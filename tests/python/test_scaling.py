"""The scaling section (scripts/sdf_report/scaling.py) on fake scripts/scaling-run lines: its
table, its two log-log plots, the note without runs, and a bad line named by file and line."""
import json

import pytest

from sdf_report import scaling
from sdf_report.document import Document


def row(n, seconds, rss):
    return {"mesh": "/data/dragon.obj", "lattice": "cc", "resolution": n, "points": n ** 3, "backend": "cuda",
            "method": "bvh", "precision": "float", "channels": ["distance", "gradient"], "dtype": "float32", "band": 0.0,
            "slabs": 1 + n // 512, "memory_budget_bytes": 8 * 2**30, "seconds": seconds, "wall_seconds": seconds + 1,
            "kernel_seconds": seconds / 10, "peak_resident_bytes": rss, "output_bytes": 16 * n ** 3,
            "disk_baseline_seconds": seconds / 2, "machine": {"cpu": "Test CPU", "cpu_threads": 16, "gpu": "NVIDIA H100"}}


def render(tmp_path, results):
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    doc = Document(str(out))
    scaling.section(doc, str(results))
    return doc.markdown(), out


def test_table_and_plots_from_scaling_lines(tmp_path):
    run = tmp_path / "results" / "scaling" / "2026-11-24T050000Z"
    run.mkdir(parents=True)
    rows = [row(32, 0.05, 300 * 2**20), row(1024, 12.0, 6 * 2**30)]
    (run / "scaling.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    md, out = render(tmp_path, tmp_path / "results")
    assert "dragon.obj, CC distance+gradient, run 2026-11-24T050000Z: Test CPU x16, GPU NVIDIA H100" in md
    assert "| 1,073,741,824 | cuda | 3 | 12 | 1.2 | 6 | 2 | 6144 | 8192 | 1.638e+04 |" in md
    assert (out / "scaling_time_2026-11-24T050000Z.png").stat().st_size > 1000
    assert (out / "scaling_memory_2026-11-24T050000Z.png").stat().st_size > 1000


def test_committed_gpu_runs_are_found_too(tmp_path):
    run = tmp_path / "results" / "gpu" / "scaling" / "2026-11-24T060000Z"
    run.mkdir(parents=True)
    (run / "scaling.jsonl").write_text(json.dumps(row(64, 0.2, 400 * 2**20)) + "\n")
    md, _ = render(tmp_path, tmp_path / "results")
    assert "run 2026-11-24T060000Z" in md


def test_note_without_runs_and_bad_lines_named(tmp_path):
    md, _ = render(tmp_path, tmp_path / "empty")
    assert "No scaling run in the results" in md
    run = tmp_path / "bad" / "scaling" / "r1"
    run.mkdir(parents=True)
    (run / "scaling.jsonl").write_text(json.dumps(row(32, 0.1, 2**20)) + "\n{not json\n")
    with pytest.raises(ValueError, match=r"scaling.jsonl:2: not a JSON line"):
        render(tmp_path, tmp_path / "bad")
