"""The report renders from the runs committed under results/ (today the published GPU runs,
results/gpu/*.json; results/gpu/scaling/ holds scaling records, not runs): they match the schema, and make a report."""
import os
import subprocess

import pytest

from conftest import REPO
from sdf_report import cli, runs


def committed_runs():
    r = subprocess.run(["git", "-C", REPO, "ls-files", "results"], capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip("not a git work tree: %s" % r.stderr.strip())
    files = r.stdout.split()
    # Published runs lie directly in results/gpu/; its subfolders hold other records (the
    # scaling runs of results/gpu/scaling/, read by scripts/sdf_report/scaling.py).
    found = [os.path.join(REPO, f) for f in files if os.path.dirname(f) == "results/gpu" and f.endswith(".json")]
    found += [os.path.join(REPO, os.path.dirname(f)) for f in files if f.endswith("/manifest.json")]
    return sorted(found)


def test_committed_runs_match_the_schema(schema):
    paths = committed_runs()
    if not paths:
        pytest.skip("no runs are committed under results/")
    for path in paths:
        runs.load_any(path, schema)


def test_report_from_the_committed_runs(tmp_path):
    paths = committed_runs()
    if not paths:
        pytest.skip("no runs are committed under results/")
    assert cli.main(["--output", str(tmp_path / "report")] + paths) == 0
    md = (tmp_path / "report" / "report.md").read_text()
    assert "from %d run(s) under the given runs" % len(paths) in md
    assert "NVIDIA H200" in md
