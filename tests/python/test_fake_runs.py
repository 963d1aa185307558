"""The fake runs the other tests use are valid, strictly (every key declared), so that the
tests exercise the report on runs shaped like run-experiment's."""
import pytest

import fake_runs
from sdf_report import runs


@pytest.mark.parametrize("kind, metrics", [
    ("reconstruction", fake_runs.reconstruction_metrics(render=True)),
    ("reconstruction", fake_runs.sweep_metrics([("a", fake_runs.reconstruction_metrics()),
                                                ("b", fake_runs.reconstruction_metrics(n=12))])),
    ("sampling", fake_runs.sampling_metrics()),
    ("speedup", fake_runs.speedup_metrics()),
    ("analytic", fake_runs.analytic_metrics()),
    ("peers", fake_runs.peers_metrics()),
    ("peers", fake_runs.peers_point_set_metrics()),
    ("peers", fake_runs.peers_honest_metrics()),
])
def test_fake_runs_match_the_schema_strictly(schema, kind, metrics):
    runs.validate(fake_runs.manifest("x", kind), metrics, "manifest.json", "metrics.json", schema, strict=True)
