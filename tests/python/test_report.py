"""scripts/make-report end to end: a full report from a fake results tree, where it is
written, and its errors."""
import json
import os
import re
import subprocess
import sys

import pytest

import fake_runs
from conftest import REPO
from sdf_report import cli

SCRIPT = os.path.join(REPO, "scripts", "make-report")


def make_report(*args):
    """Runs scripts/make-report with this interpreter (the one that has numpy and matplotlib)."""
    return subprocess.run([sys.executable, SCRIPT] + [str(a) for a in args], capture_output=True, text=True)


def test_full_report_from_a_fake_results_tree(tmp_path):
    fake_runs.full_tree(tmp_path / "results")
    out = tmp_path / "report"
    r = make_report("--results", tmp_path / "results", "--output", out)
    assert r.returncode == 0, r.stderr
    assert "(6 runs)" in r.stdout
    md = (out / "report.md").read_text()
    # Every section, the later dragon run only, a note that this is not the published report.
    for heading in ("## Runs", "## Sampling times and throughput", "## Table 3-1: meshes",
                    "## Table 3-2: sampling times and speedups", "## Table 4-1", "## Error versus sample count",
                    "## Reconstruction errors per mesh and interpolator", "## Image grids",
                    "## Exact sampling against the peer libraries"):
        assert heading in md, heading
    assert "A local report of the runs on this machine" in md
    assert md.count("| dragon | reconstruction |") == 1
    assert "passed (41 ok, 0 not comparable)" in md
    assert "| cc-8x8x8/catmull_rom/fd | A | 0.02 | 0.2 |" in md  # r2 (scale 1), not r1 (scale 100)
    assert "| dragon_32k | box-cc-8 | cc 8x8x8 |" in md
    # Every image the Markdown names exists, and the HTML embeds them all: nothing is fetched.
    names = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md)
    assert sorted(set(names)) == ["grid_dragon_front.png", "grid_pawn_sweep-200k_front.png",
                                  "grid_pawn_sweep-33k_front.png", "heat_map_scale_20.png", "ml_error_vs_samples.png",
                                  "pawn_sweep_error_vs_samples.png", "speedup_vs_size_speedup.png"]
    assert names.count("heat_map_scale_20.png") == 3  # under each grid
    for name in names:
        assert (out / name).is_file(), name
    page = (out / "index.html").read_text()
    sources = re.findall(r"<img src=\"([^\"]*)\"", page)
    assert len(sources) == len(names) and all(s.startswith("data:image/png;base64,") for s in sources)
    assert not re.search(r"(src|href)=\"(?!data:)", page)
    assert not re.search(r"<link|<script|@import|url\(", page)


def test_default_output_is_the_local_report_and_publish_the_committed_one():
    assert cli.parse_args([]).output == os.path.join(REPO, "results", "report-local")
    assert cli.parse_args(["--publish"]).output == os.path.join(REPO, "results", "report")
    assert cli.parse_args(["--output", os.path.join(REPO, "results", "report")]).output == cli.PUBLISHED
    with pytest.raises(SystemExit):
        cli.parse_args(["--publish", "--output", "/tmp/elsewhere"])


def test_the_local_report_is_ignored_by_git():
    r = subprocess.run(["git", "-C", REPO, "check-ignore", "-q", "results/report-local/index.html"])
    if r.returncode == 128:
        pytest.skip("not a git work tree")
    assert r.returncode == 0


def test_an_invalid_run_fails_naming_file_and_key(tmp_path):
    metrics = fake_runs.reconstruction_metrics()
    del metrics["probes"]["h_ref"]
    path = fake_runs.write_run(tmp_path / "results", "dragon", "reconstruction", metrics)
    r = make_report("--results", tmp_path / "results", "--output", tmp_path / "report")
    assert r.returncode == 1
    assert "%s: does not match the run schema" % os.path.join(path, "metrics.json") in r.stderr
    assert "key 'probes.h_ref': missing (expected number: the coarsest lattice spacing" in r.stderr
    assert not (tmp_path / "report").exists()
    r = make_report("--results", tmp_path / "results", "--output", tmp_path / "report", "--skip-invalid")
    assert r.returncode == 0, r.stderr
    assert "warning: skipping an invalid run" in r.stderr
    assert "Left out (--skip-invalid)" in (tmp_path / "report" / "report.md").read_text()


def test_refuses_to_write_into_a_directory_that_holds_no_report(tmp_path):
    (tmp_path / "photos").mkdir()
    (tmp_path / "photos" / "holiday.png").write_bytes(b"not ours")
    r = make_report("--results", tmp_path / "none", "--output", tmp_path / "photos")
    assert r.returncode != 0
    assert "holds no report" in r.stderr
    assert (tmp_path / "photos" / "holiday.png").read_bytes() == b"not ours"


def test_a_new_report_replaces_the_old_plots(tmp_path):
    fake_runs.full_tree(tmp_path / "results")
    out = tmp_path / "report"
    assert make_report("--results", tmp_path / "results", "--output", out).returncode == 0
    (out / "old_plot.png").write_bytes(b"stale")
    r = make_report("--results", tmp_path / "results", "--output", out, tmp_path / "results" / "ml" / "r1")
    assert r.returncode == 0, r.stderr
    assert sorted(os.listdir(out)) == ["index.html", "ml_error_vs_samples.png", "report.md"]
    assert "No speedup run in the results" in (out / "report.md").read_text()


def test_no_runs_at_all(tmp_path):
    r = make_report("--results", tmp_path / "nothing", "--output", tmp_path / "report")
    assert r.returncode == 0, r.stderr
    assert "No runs found" in (tmp_path / "report" / "report.md").read_text()


def test_only_section_peers_rewrites_that_section_from_the_runs_given(tmp_path):
    fake_runs.full_tree(tmp_path / "results")
    out = tmp_path / "report"
    assert make_report("--results", tmp_path / "results", "--output", out).returncode == 0
    # a report whose other sections cannot be regenerated: only the peers section is rewritten
    md = (out / "report.md").read_text().replace("## Exact sampling against the peer libraries",
                                                 "## Kept section\n\nkept text\n\n## Exact sampling against the peer libraries")
    (out / "report.md").write_text(md)
    later = tmp_path / "later"
    metrics = fake_runs.peers_metrics()
    metrics["summary"][0]["query_speedup"] = 7.25
    run = fake_runs.write_run(later, "peers", "peers", metrics, run_id="r9", finished="2026-03-01T00:00:00Z")
    old_overview = (out / "report.md").read_text().split("\n## ", 2)[1]
    assert "| peers | peers | 2026-02-01T000000Z-00000000 |" in old_overview
    for _ in range(2):  # twice: still one section, in its place
        r = make_report("--results", tmp_path / "empty", "--output", out, "--only-section", "peers", run)
        assert r.returncode == 0, r.stderr
        md = (out / "report.md").read_text()
        html = (out / "index.html").read_text()
        assert "kept text" in md and md.count("## Exact sampling against the peer libraries") == 1
        with open(os.path.join(run, "manifest.json")) as f:
            run_id = json.load(f)["run_id"]
        assert "| 7.25 | 4.75 |" in md and "| 5 | 4.75 |" not in md  # the old run's summary row is gone
        assert "rewritten alone" in md and "runs peers %s, and with it their entries in the overview" % run_id in md
        assert "7.25" in html and html.count("<h2>Exact sampling against the peer libraries") == 1
        assert "## Where the user waits" in md and md.index("## Exact sampling") < md.index("## Where the user waits")
        # the overview lists the new peers run in place of the old one, and keeps the others' rows
        overview = md.split("\n## ", 2)[1]
        assert overview.startswith("Runs\n")
        assert overview.count("| peers | peers |") == 1 and "| peers | peers | 2026-03-01T000000Z-00000000 |" in overview
        assert "2026-02-01T000000Z-00000000 | " in overview.split("| peers | peers |")[0]  # the rows before it kept
        assert [line.split(" | ")[0] for line in overview.split("\n") if line.startswith("| ")] == \
               [line.split(" | ")[0] for line in old_overview.split("\n") if line.startswith("| ")]
        html_overview = html.split("<h2>Runs</h2>", 1)[1].split("<h2>", 1)[0]
        assert "<td class=\"text\">2026-03-01T000000Z-00000000</td>" in html_overview
        assert html_overview.count("<tr><td class=\"text\">peers</td>") == 1
    # no peers run: an error naming where it looked
    r = make_report("--results", tmp_path / "empty", "--output", out, "--only-section", "peers")
    assert r.returncode != 0 and "no peers run under" in r.stderr


def _mark_dirty(run):
    path = os.path.join(run, "manifest.json")
    with open(path) as f:
        m = json.load(f)
    m["provenance"]["git"]["dirty"] = True
    with open(path, "w") as f:
        json.dump(m, f)


def test_overview_notes_dirty_runs_and_only_section_keeps_every_run_given(tmp_path):
    fake_runs.full_tree(tmp_path / "results")
    _mark_dirty(os.path.join(tmp_path / "results", "peers", "r1"))
    out = tmp_path / "report"
    assert make_report("--results", tmp_path / "results", "--output", out).returncode == 0
    assert "> Runs marked dirty" in (out / "report.md").read_text()
    # two peers runs given: both listed in the overview, where the peers row was
    later = tmp_path / "later"
    a = fake_runs.write_run(later, "peers", "peers", fake_runs.peers_metrics(), run_id="a", finished="2026-03-01T00:00:00Z")
    b = fake_runs.write_run(later, "peers", "peers", fake_runs.peers_metrics(), run_id="b", finished="2026-03-02T00:00:00Z")
    before = [line.split(" | ")[0] for line in (out / "report.md").read_text().split("\n## ", 2)[1].split("\n")
              if line.startswith("| ")]
    r = make_report("--results", tmp_path / "empty", "--output", out, "--only-section", "peers", a, b)
    assert r.returncode == 0, r.stderr
    overview = (out / "report.md").read_text().split("\n## ", 2)[1]
    names = [line.split(" | ")[0] for line in overview.split("\n") if line.startswith("| ")]
    at = before.index("| peers")
    assert names == before[:at] + ["| peers", "| peers"] + before[at + 1:]
    assert "2026-03-01T000000Z-00000000" in overview and "2026-03-02T000000Z-00000000" in overview
    assert "> Runs marked dirty" not in overview  # the dirty peers run is no longer listed


def test_only_section_refuses_an_overview_it_cannot_read(tmp_path):
    fake_runs.full_tree(tmp_path / "results")
    out = tmp_path / "report"
    assert make_report("--results", tmp_path / "results", "--output", out).returncode == 0
    md = (out / "report.md").read_text()
    md = md.replace("| peers | peers |", "| peers | peers | extra |", 1)
    (out / "report.md").write_text(md)
    run = os.path.join(tmp_path / "results", "peers", "r1")
    r = make_report("--results", tmp_path / "empty", "--output", out, "--only-section", "peers", run)
    assert r.returncode == 1
    assert "report.md" in r.stderr and "expected 9" in r.stderr and "Traceback" not in r.stderr
    assert (out / "report.md").read_text() == md  # left as it was
