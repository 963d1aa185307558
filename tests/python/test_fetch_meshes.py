"""scripts/fetch-meshes: installs only verified files, names what is missing or wrong, and
(where this machine has the workplace's mirror ../shared/sources) installs the real files with
the checksums the script pins."""
import hashlib
import importlib.machinery
import importlib.util
import os

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(REPO, "scripts", "fetch-meshes")
MIRROR = os.path.join(os.path.dirname(REPO), "shared", "sources")


def load_script():
    loader = importlib.machinery.SourceFileLoader("fetch_meshes", SCRIPT)
    spec = importlib.util.spec_from_loader("fetch_meshes", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def run(module, monkeypatch, *args):
    monkeypatch.setattr("sys.argv", ["fetch-meshes", *args])
    return module.main()


@pytest.fixture
def fake(tmp_path, monkeypatch):
    """The script with a two-file table whose checksums are those of files made here."""
    module = load_script()
    mirror = tmp_path / "mirror"
    mirror.mkdir()
    rows = []
    for name, upstream, text in [("a.obj", "models/a.obj", b"v 0 0 0\n"), ("b.ply.gz", "x/b.ply.gz", b"\x1f\x8b fake")]:
        (mirror / os.path.basename(upstream)).write_bytes(text)
        rows.append((name, "owner/repo", "0" * 40, upstream, hashlib.sha256(text).hexdigest(), "a study"))
    monkeypatch.setattr(module, "SOURCES", rows)
    return module, mirror, tmp_path / "dest"


def test_mirror_installs_every_verified_file(fake, monkeypatch, capsys):
    module, mirror, dest = fake
    assert run(module, monkeypatch, "--from", str(mirror), "--dest", str(dest)) == 0
    assert sorted(os.listdir(dest)) == ["a.obj", "b.ply.gz"]  # no staging left behind
    assert (dest / "a.obj").read_bytes() == b"v 0 0 0\n"
    # A second run finds them installed and verified.
    assert run(module, monkeypatch, "--from", str(mirror), "--dest", str(dest)) == 0
    assert "already installed" in capsys.readouterr().out


def test_a_file_with_other_bytes_is_refused_and_not_installed(fake, monkeypatch, capsys):
    module, mirror, dest = fake
    (mirror / "a.obj").write_bytes(b"v 0 0 1\n")  # same size, one byte differs
    assert run(module, monkeypatch, "--from", str(mirror), "--dest", str(dest)) == 1
    err = capsys.readouterr().err
    assert "a.obj: SHA-256" in err and "expected" in err and "not installed" in err
    assert not (dest / "a.obj").exists()
    assert (dest / "b.ply.gz").exists()


def test_a_damaged_installed_file_is_replaced(fake, monkeypatch):
    module, mirror, dest = fake
    dest.mkdir()
    (dest / "a.obj").write_bytes(b"garbage")
    assert run(module, monkeypatch, "--from", str(mirror), "--dest", str(dest)) == 0
    assert (dest / "a.obj").read_bytes() == b"v 0 0 0\n"


def test_a_missing_file_is_named_with_its_users(fake, monkeypatch, capsys):
    module, mirror, dest = fake
    (mirror / "b.ply.gz").unlink()
    assert run(module, monkeypatch, "--from", str(mirror), "--dest", str(dest)) == 1
    err = capsys.readouterr().err
    assert "b.ply.gz: not in the mirror" in err and "needed by: a study" in err


def test_a_mirror_that_is_not_a_directory_is_refused(fake, monkeypatch, tmp_path):
    module, _, dest = fake
    with pytest.raises(SystemExit, match="not a directory"):
        run(module, monkeypatch, "--from", str(tmp_path / "nowhere"), "--dest", str(dest))


def test_every_study_mesh_is_in_the_table():
    """No config names a mesh file that fetch-meshes does not provide."""
    import json
    import re
    script = load_script()
    provided = {row[0] for row in script.SOURCES} | set(script.DERIVED)
    named = set()
    for root, _, files in os.walk(os.path.join(REPO, "configs")):
        for f in files:
            text = open(os.path.join(root, f), encoding="utf-8").read()
            named |= set(re.findall(r'"mesh":\s*"([^"]+)"', text))
            named |= set(re.findall(r'"mesh":\s*\{\s*"file":\s*"([^"]+)"', text))
    files = {m for m in named if not m.startswith("shape:")}
    assert files and files <= provided, files - provided


def test_a_derived_file_keeps_the_geometry_of_its_source(tmp_path, monkeypatch, capsys):
    """dragon-legacy.obj from a photon-dragon.obj: header replaced, v/f tokens kept; a source
    whose geometry differs is not derived."""
    module = load_script()
    geometry = "v 1 2 3\nv 4 5 6\nv 7 8 9\nf 1 2 3\n"
    source_text = "# photon header\nv 1 2 3\nv 4 5 6   \nv 7 8 9\nf 1/1 2/2 3/3\n"
    digest = hashlib.sha256(geometry.encode()).hexdigest()
    monkeypatch.setattr(module, "DERIVED", {"legacy.obj": ("src.obj", "# new header\n", digest)})
    (tmp_path / "src.obj").write_text(source_text)
    staging = tmp_path / "staging"
    staging.mkdir()
    assert module.derive("legacy.obj", str(tmp_path), str(staging)) is None
    assert (tmp_path / "legacy.obj").read_text() == "# new header\n" + geometry
    (tmp_path / "src.obj").write_text(source_text.replace("v 7 8 9", "v 7 8 10"))
    (tmp_path / "legacy.obj").unlink()
    assert "geometry SHA-256" in module.derive("legacy.obj", str(tmp_path), str(staging))
    assert not (tmp_path / "legacy.obj").exists()


def test_the_thesis_dragon_derivation_matches_the_workplace_copy():
    """The pinned geometry digest is that of the reference dragon-legacy.obj (where present)."""
    module = load_script()
    reference = os.path.join(os.path.dirname(REPO), "shared", "meshes", "dragon-legacy.obj")
    if not os.path.isfile(reference):
        pytest.skip("no ../shared/meshes/dragon-legacy.obj on this machine")
    h = hashlib.sha256()
    for line in module.geometry_lines(reference):
        h.update(line.encode())
    assert h.hexdigest() == module.DERIVED["dragon-legacy.obj"][2]


@pytest.mark.skipif(not os.path.isdir(MIRROR), reason="no ../shared/sources mirror on this machine")
def test_the_workplace_mirror_gives_the_pinned_files(tmp_path, monkeypatch):
    module = load_script()
    available = [row for row in module.SOURCES if os.path.isfile(os.path.join(MIRROR, os.path.basename(row[3])))]
    assert any(row[0] == "dragon_vrip_res2.ply.gz" for row in available)
    monkeypatch.setattr(module, "SOURCES", available)
    assert run(module, monkeypatch, "--from", MIRROR, "--dest", str(tmp_path)) == 0
    for name, *_, digest, _ in available:
        assert hashlib.sha256((tmp_path / name).read_bytes()).hexdigest() == digest
