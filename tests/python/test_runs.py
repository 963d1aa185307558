"""Finding and loading runs: the latest of each experiment, staging directories skipped,
published GPU runs read, unreadable or invalid runs reported by file and key."""
import json
import os

import pytest

import fake_runs
from sdf_report import runs
from sdf_report.schema import RunFileError


def test_latest_run_of_each_experiment_hidden_directories_skipped(tmp_path, schema):
    fake_runs.write_run(tmp_path, "dragon", "reconstruction", fake_runs.reconstruction_metrics(), run_id="a",
                        finished="2026-01-01T00:00:00Z")
    fake_runs.write_run(tmp_path, "dragon", "reconstruction", fake_runs.reconstruction_metrics(), run_id="b",
                        finished="2026-03-01T00:00:00Z")
    fake_runs.write_run(tmp_path, "ml", "analytic", fake_runs.analytic_metrics())
    os.makedirs(tmp_path / "dragon" / ".c.partial.1")  # a run being written
    os.makedirs(tmp_path / ".staging" / "x")
    (tmp_path / "report-local").mkdir()  # a report directory holds no runs
    (tmp_path / "report-local" / "report.md").write_text("# old\n")
    found, skipped = runs.collect(str(tmp_path), [], schema)
    assert [(r.name, os.path.basename(r.path)) for r in found] == [("dragon", "b"), ("ml", "r1")]
    assert skipped == []


def test_explicit_runs_are_all_reported_in_order(tmp_path, schema):
    a = fake_runs.write_run(tmp_path, "dragon", "reconstruction", fake_runs.reconstruction_metrics(), run_id="a")
    b = fake_runs.write_run(tmp_path, "dragon", "reconstruction", fake_runs.reconstruction_metrics(), run_id="b")
    found, _ = runs.collect(str(tmp_path), [b, a], schema)
    assert [r.path for r in found] == [b, a]


def test_missing_metrics_file_is_an_error_naming_it(tmp_path, schema):
    path = fake_runs.write_run(tmp_path, "ml", "analytic", fake_runs.analytic_metrics())
    os.remove(os.path.join(path, "metrics.json"))
    with pytest.raises(RunFileError) as e:
        runs.collect(str(tmp_path), [], schema)
    assert str(e.value) == "%s: missing" % os.path.join(path, "metrics.json")


def test_unparsable_json_is_an_error_naming_the_file(tmp_path, schema):
    path = fake_runs.write_run(tmp_path, "ml", "analytic", fake_runs.analytic_metrics())
    with open(os.path.join(path, "manifest.json"), "w") as f:
        f.write("{\"name\": ")
    with pytest.raises(RunFileError) as e:
        runs.load_run_dir(path, schema)
    assert str(e.value).startswith(os.path.join(path, "manifest.json") + ": cannot read it as JSON")


def test_invalid_run_fails_or_is_skipped_with_a_warning(tmp_path, schema):
    metrics = fake_runs.analytic_metrics()
    metrics["table_4_1"]["ratio_rms"] = None
    bad = fake_runs.write_run(tmp_path, "ml", "analytic", metrics)
    fake_runs.write_run(tmp_path, "speedup", "speedup", fake_runs.speedup_metrics())
    with pytest.raises(RunFileError) as e:
        runs.collect(str(tmp_path), [], schema)
    assert os.path.join(bad, "metrics.json") in str(e.value)
    assert "key 'table_4_1.ratio_rms': expected number, got null" in str(e.value)
    warnings = []
    found, skipped = runs.collect(str(tmp_path), [], schema, skip_invalid=True, warn=warnings.append)
    assert [r.name for r in found] == ["speedup"]
    assert len(skipped) == 1 and len(warnings) == 1 and "table_4_1.ratio_rms" in warnings[0]


def test_published_gpu_run_is_read_from_gpu_json(tmp_path, schema):
    os.makedirs(tmp_path / "gpu")
    published = {"format": "sdf-gpu-results", "version": 1, "source_commit": "3792575", "note": "lent H200",
                 "manifest": fake_runs.manifest("gpu_kernels", "speedup", gpu={"name": "NVIDIA H200"}),
                 "metrics": fake_runs.speedup_metrics()}
    (tmp_path / "gpu" / "2026-11-21-h200.json").write_text(json.dumps(published))
    found, _ = runs.collect(str(tmp_path), [], schema)
    assert len(found) == 1
    run = found[0]
    assert run.name == "gpu_kernels" and run.published == {"source_commit": "3792575", "note": "lent H200"}
    published["format"] = "something else"
    (tmp_path / "gpu" / "2026-11-21-h200.json").write_text(json.dumps(published))
    with pytest.raises(RunFileError) as e:
        runs.collect(str(tmp_path), [], schema)
    assert "key 'format': expected a published run" in str(e.value)


def test_sweep_points_have_their_own_directories(tmp_path, schema):
    path = fake_runs.write_run(tmp_path, "pawn_sweep", "reconstruction", fake_runs.sweep_metrics(
        [("pawn_sweep-33k", fake_runs.reconstruction_metrics()), ("pawn_sweep-200k", fake_runs.reconstruction_metrics())]))
    run = runs.load_run_dir(path, schema)
    assert run.is_sweep
    assert [(p.name, p.dir) for p in run.points] == [("pawn_sweep-33k", os.path.join(path, "pawn_sweep-33k")),
                                                     ("pawn_sweep-200k", os.path.join(path, "pawn_sweep-200k"))]
    single = runs.load_run_dir(fake_runs.write_run(tmp_path, "dragon", "reconstruction",
                                                   fake_runs.reconstruction_metrics()), schema)
    assert [(p.name, p.dir) for p in single.points] == [("dragon", single.path)]


def test_a_path_that_is_no_run(tmp_path, schema):
    with pytest.raises(RunFileError) as e:
        runs.load_any(str(tmp_path / "nothing"), schema)
    assert "neither a run directory nor a published run file" in str(e.value)
