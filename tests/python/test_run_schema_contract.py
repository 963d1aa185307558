"""The contract between run-experiment and the report: every experiment kind, run at a tiny
size by the real binary, writes what harness/schema/run_schema.json declares, strictly (no
key missing, mistyped or undeclared), and the report renders from those runs.

CTest's run_schema_contract runs this file with RUN_EXPERIMENT set to the built
run-experiment (tests/python/CMakeLists.txt); without it the test is skipped."""
import glob
import json
import os
import subprocess

import pytest

from conftest import HERE, REPO
from sdf_report import cli, runs

CONFIGS = sorted(glob.glob(os.path.join(HERE, "contract_configs", "*.json"))) + \
    [os.path.join(REPO, "configs", "ci_smoke.json")]


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    exe = os.environ.get("RUN_EXPERIMENT")
    if not exe:
        pytest.skip("RUN_EXPERIMENT (the run-experiment binary) is not set: CTest's run_schema_contract sets it")
    assert os.access(exe, os.X_OK), "RUN_EXPERIMENT=%s is not an executable" % exe
    root = tmp_path_factory.mktemp("contract")
    env = dict(os.environ, SDF_CACHE_DIR=str(root / "cache"))
    for config in CONFIGS:
        # ci_smoke has a baseline: its check's outcome, once the manifest records it ("check"),
        # is validated too.
        check = ["--check"] if config.endswith("ci_smoke.json") else []
        r = subprocess.run([exe, config, "--output-root", str(root / "results"), "--quiet"] + check, capture_output=True,
                           text=True, env=env)
        assert r.returncode == 0, "%s: %s%s" % (config, r.stdout, r.stderr)
    return root / "results"


def test_every_kind_is_covered(schema):
    kinds = set()
    for config in CONFIGS:
        with open(config) as f:
            text = "".join(line for line in f if not line.lstrip().startswith("//"))
        kinds.add(json.loads(text)["kind"])
    assert kinds == set(schema["metrics"])


def test_what_run_experiment_writes_matches_the_schema_strictly(results, schema):
    found = runs.candidate_paths(str(results))
    assert len(found) == len(CONFIGS)
    for path in found:
        runs.load_run_dir(path, schema, strict=True)


def test_the_report_renders_from_those_runs(results, tmp_path):
    assert cli.main(["--results", str(results), "--output", str(tmp_path / "report")]) == 0
    md = (tmp_path / "report" / "report.md").read_text()
    assert "from %d run(s)" % len(CONFIGS) in md
    assert "| ci_smoke | cc-14x14x14 | cc 14x14x14 | 2,744 |" in md
    assert "(= catmull_rom: same function)" in md


def test_a_checked_run_records_its_check(results):
    """run-experiment --check writes the check's outcome into the stored manifest."""
    checked = [p for p in runs.candidate_paths(str(results)) if "ci_smoke" in p]
    assert len(checked) == 1
    with open(os.path.join(checked[0], "manifest.json")) as f:
        manifest = json.load(f)
    assert manifest["check"]["passed"] is True
    assert manifest["check"]["failed"] == 0 and manifest["check"]["ok"] > 0
    assert manifest["check"]["baseline"].endswith("results/baselines/ci_smoke.json")


def test_narrow_band_rows_are_measured_against_the_exact_field(results, schema):
    """The peers run's narrow-band rows (band_resolutions): our sparse band's active voxels are
    its band points, every value exact (the exact field's own query at those points) with no
    wrong sign; OpenVDB's and NanoVDB's rows, where built, are measured at their own voxels."""
    paths = [p for p in runs.candidate_paths(str(results)) if "contract_peers" in p]
    assert len(paths) == 1
    run = runs.load_run_dir(paths[0], schema, strict=True)
    rows = [r for point in run.points for r in point.metrics["rows"] if " band " in r["resolution"]]
    assert {r["method"] for r in rows} == {"band_cpu", "band_gpu", "openvdb_band", "nanovdb"}
    ours = [r for r in rows if r["method"] == "band_cpu"]
    assert len(ours) == 1
    band = ours[0]
    width = band["level_set"]["width"]
    assert band["level_set"]["width_voxels"] == 3
    assert band["level_set"]["lattice_points"] == 24 ** 3
    assert 0 < band["active_voxels"] < 24 ** 3
    assert band["compared_points"] == band["active_voxels"]
    assert band["max_abs_error"] <= 1e-12 * width, band["max_abs_error"]
    assert band["sign_disagreements"] == 0
    assert band["passes_check"] is True
    for row in rows:
        if "status" in row:
            continue
        assert row["active_voxels"] > 0 and row["compared_points"] == row["active_voxels"], row["method"]
        if row["method"] == "openvdb_band":  # float values, its own band: within a spacing of the exact field
            assert row["max_abs_error"] < width / 3, row["max_abs_error"]
        if row["method"] == "nanovdb":
            assert row["sign_disagreements"] == "n/a (unsigned)"
