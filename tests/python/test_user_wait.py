"""Where the user waits: the report's section (scripts/sdf_report/user_wait.py) on fake
scripts/user-wait records (the table with wall beside kernel time and the peer, rows not run
with their reason, the one-liner table, the plot, the latest run per machine, a bad file named
by file and key), and the parts of scripts/user-wait that need no built tools: the CAD-like box
it renders is closed, outward and has the triangle count it claims, and a peers row that did
not run becomes a row "not run" with the peer's status."""
import importlib.machinery
import importlib.util
import json
import os
from fractions import Fraction

import pytest

from conftest import REPO
from sdf_report import user_wait
from sdf_report.document import Document


def load_driver():
    loader = importlib.machinery.SourceFileLoader("user_wait_driver", os.path.join(REPO, "scripts", "user-wait"))
    spec = importlib.util.spec_from_loader(loader.name, loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def record(run_id, gpu, started):
    rows = [
        {"id": "points_16m", "status": "measured", "title": "one point-query call, 16.8M uniform points",
         "wall_seconds": 1.4, "kernel_seconds": 0.0176, "kernel_what": "device time", "details": {}},
        {"id": "query_1_point", "status": "measured", "title": "Python .query of 1 point", "wall_seconds": 2.2e-5,
         "kernel_seconds": None, "kernel_what": "none reported",
         "details": {"build_seconds": 0.3, "peak_resident_bytes": 2 * 2**20, "backend": "cpu"}},
        {"id": "cpu_bvh_fcpw", "status": "measured", "title": "CPU BVH against FCPW", "wall_seconds": 0.5,
         "kernel_seconds": 0.4, "kernel_what": "the query",
         "peer": {"name": "FCPW", "build_seconds": 0.03, "query_seconds": 0.4},
         "details": {"ours": {"build_seconds": 0.1, "query_seconds": 0.4}}},
        {"id": "sample_1024", "status": "not run", "reason": "no GPU on this machine"},
    ]
    one_liner = {"id": "one_liner", "status": "measured", "points": 100000, "triangles": 99902, "mesh": "dragon.obj",
                 "sampler": "cpu/bvh/brick", "sign": "pseudonormal",
                 "rows": [{"method": "sl.sdf(mesh, P), the one-liner", "build_seconds": 0.0, "query_seconds": 2.0,
                           "total_seconds": 2.0, "note": "", "max_abs_error": 0.0, "median_abs_error": 0.0,
                           "wrong_sign_fraction": 0.0},
                          {"method": "Open3D 0.16.1 RaycastingScene", "build_seconds": 0.001, "query_seconds": 4.0,
                           "total_seconds": 4.001, "note": "float32", "max_abs_error": 3e-8, "max_abs_error_unsigned": 1e-8, "median_abs_error": 2e-9,
                           "wrong_sign_fraction": 0.08}],
                 "not_run": [{"method": "trimesh.proximity.signed_distance", "reason": "not packaged in Debian 12"}]}
    return {"format": "sdf-user-wait", "version": 1, "run_id": run_id, "started": started, "commit": "0123456789abcdef",
            "build": "/x/build", "load_start": [3.0, 2.0, 1.0], "load_end": [4.0, 2.0, 1.0],
            "machine": {"cpu": "Test CPU", "cpu_threads": 2, "gpu": gpu, "host": "h"}, "rows": rows, "one_liner": one_liner}


def write(results, sub, run):
    path = results.joinpath(*sub, run["run_id"])
    path.mkdir(parents=True)
    (path / "user_wait.json").write_text(json.dumps(run))


def render(tmp_path, results):
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    doc = Document(str(out))
    user_wait.section(doc, str(results))
    return doc.markdown(), out


def test_table_one_liner_and_plot_per_machine(tmp_path):
    results = tmp_path / "results"
    write(results, ["user_wait"], record("r1", None, "2026-11-25T10:00:00+00:00"))
    write(results, ["user_wait"], record("r2", None, "2026-11-25T11:00:00+00:00"))  # same machine, later: shown
    write(results, ["gpu", "user_wait"], record("g1", "NVIDIA H100 80GB HBM3", "2026-11-25T09:00:00+00:00"))
    md, out = render(tmp_path, results)
    assert "Run r2: Test CPU x2, GPU none" in md and "Run r1" not in md
    assert "Run g1: Test CPU x2, GPU NVIDIA H100 80GB HBM3" in md
    assert "Made on a loaded machine (load above its 2 hardware threads)" in md
    assert "| points_16m | one point-query call, 16.8M uniform points | 0.0176 | 1.4 | 79.55 | device time | - | - | - |" in md
    assert "| query_1_point | Python .query of 1 point | n/a | 2.200e-05 | n/a |" in md
    assert "| peak RSS 2 MiB; SDF build 0.3 s; backend cpu |" in md
    assert "FCPW: build 0.03 + query 0.4 | query 1, build + query 1.163 |" in md
    assert "| sample_1024 | not run: no GPU on this machine |" in md
    assert "| Open3D 0.16.1 RaycastingScene | 0.001 | 4 | 4.001 | 2.5e+04 | 3.000e-08 | 1.000e-08 | 2.000e-09 | 8.000% | float32 |" in md
    assert "| trimesh.proximity.signed_distance | - |" in md and "not run: not packaged in Debian 12" in md
    assert (out / "user_wait_wall_vs_kernel.png").stat().st_size > 1000


def test_note_without_runs_and_bad_files_named(tmp_path):
    md, _ = render(tmp_path, tmp_path / "empty")
    assert "No user-wait run in the results" in md
    run = record("bad", None, "2026-11-25T10:00:00+00:00")
    del run["rows"][0]["wall_seconds"]
    write(tmp_path / "bad", ["user_wait"], run)
    with pytest.raises(user_wait.UserWaitFileError, match=r"user_wait.json: rows\[0\]: key 'wall_seconds': missing"):
        render(tmp_path, tmp_path / "bad")
    run = dict(record("old", None, "2026-11-25T10:00:00+00:00"), format="something else")
    write(tmp_path / "other", ["user_wait"], run)
    with pytest.raises(user_wait.UserWaitFileError, match="key 'format'"):
        render(tmp_path, tmp_path / "other")


def read_obj(path):
    vertices, faces = [], []
    for line in open(path):
        if line.startswith("v "):
            vertices.append([Fraction(x) for x in line.split()[1:]])
        elif line.startswith("f "):
            faces.append([int(i) - 1 for i in line.split()[1:]])
    return vertices, faces


def test_cad_box_is_closed_outward_and_counted(tmp_path):
    driver = load_driver()
    path = tmp_path / "box.obj"
    assert driver.write_cad_box(str(path), parts=(5, 4, 3)) == 8 * (5 + 4 + 3)
    v, f = read_obj(path)
    assert len(f) == 96
    edges = {}
    for t in f:
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            edges[(a, b)] = edges.get((a, b), 0) + 1
    assert all(n == 1 and edges.get((b, a)) == 1 for (a, b), n in edges.items())  # closed, consistently oriented
    volume = Fraction(0)
    for a, b, c in f:  # exact: the coordinates are decimals written with %.3f
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = v[a], v[b], v[c]
        volume += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
    assert volume / 6 == Fraction(5 * 4 * 3, 1000 ** 3)  # the box's volume, positive: outward
    assert driver.write_cad_box(str(tmp_path / "default.obj")) == 13000


def test_peers_rows_that_did_not_run_are_not_run(tmp_path):
    driver = load_driver()
    metrics = {"rows": [{"method": "fcpw", "resolution": "64x64x64", "status": "not built"},
                        {"method": "bvh_cpu", "resolution": "64x64x64", "build_seconds": 0.1, "query_seconds": 0.4}]}
    with pytest.raises(driver.NotRun, match="fcpw: not built"):
        driver.peer_row(metrics, "fcpw", "64x64x64")
    assert driver.peer_row(metrics, "bvh_cpu", "64x64x64")["query_seconds"] == 0.4
    with pytest.raises(RuntimeError, match="no cubql row"):
        driver.peer_row(metrics, "cubql", "64x64x64")


def test_make_report_takes_user_wait_records_and_rewrites_the_section_alone(tmp_path):
    from sdf_report import cli
    empty = tmp_path / "empty-results"
    empty.mkdir()
    gpu = tmp_path / "g1.json"
    gpu.write_text(json.dumps(record("g1", "NVIDIA H100 80GB HBM3", "2026-11-25T09:00:00+00:00")))
    out = tmp_path / "report"
    assert cli.main(["--results", str(empty), "--output", str(out), str(gpu)]) == 0
    md = (out / "report.md").read_text()
    assert "Run g1: Test CPU x2, GPU NVIDIA H100 80GB HBM3" in md and "from 0 run(s)" in md
    # a report whose other sections cannot be regenerated: only the section is rewritten
    text = md.replace("## Where the user waits", "## Kept section\n\nkept text\n\n## Where the user waits")
    (out / "report.md").write_text(text)
    later = tmp_path / "g2.json"
    later.write_text(json.dumps(record("g2", "NVIDIA H100 80GB HBM3", "2026-11-25T12:00:00+00:00")))
    for _ in range(2):  # twice: the same text
        assert cli.main(["--results", str(empty), "--output", str(out), "--only-section", "user-wait", str(later)]) == 0
        md = (out / "report.md").read_text()
        html = (out / "index.html").read_text()
        assert "kept text" in md and "Run g2" in md and "Run g1" not in md and md.count("## Where the user waits") == 1
        assert "Run g2" in html and html.count("<h2>Where the user waits") == 1 and html.rstrip().endswith("</body></html>")


def test_only_section_needs_an_existing_report(tmp_path):
    from sdf_report import cli
    with pytest.raises(SystemExit, match="needs an existing report"):
        cli.main(["--results", str(tmp_path), "--output", str(tmp_path / "nothing"), "--only-section", "user-wait"])


def test_publish_gpu_results_copies_a_gpu_record_once(tmp_path):
    import subprocess
    import sys
    script = os.path.join(REPO, "scripts", "publish-gpu-results")
    gpu = tmp_path / "g.json"
    gpu.write_text(json.dumps(record("2026-11-25T192119Z", "NVIDIA H100 80GB HBM3", "2026-11-25T19:21:19+00:00")))
    out = tmp_path / "gpu"
    r = subprocess.run([sys.executable, script, str(gpu), "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    target = out / "user_wait" / "2026-11-25T192119Z" / "user_wait.json"
    assert json.loads(target.read_text()) == json.loads(gpu.read_text())
    r = subprocess.run([sys.executable, script, str(gpu), "--out", str(out)], capture_output=True, text=True)
    assert r.returncode != 0 and "refusing to overwrite" in r.stderr
    cpu = tmp_path / "c.json"
    cpu.write_text(json.dumps(record("c1", None, "2026-11-25T19:21:19+00:00")))
    r = subprocess.run([sys.executable, script, str(cpu), "--out", str(out)], capture_output=True, text=True)
    assert r.returncode != 0 and "names no GPU" in r.stderr
