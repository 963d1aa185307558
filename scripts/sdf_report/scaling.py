"""Time and memory against lattice size (issue 14): the runs of scripts/scaling-run, JSON lines
under results/scaling/<run-id>/scaling.jsonl (local) or results/gpu/scaling/<run-id>/ (committed
runs of the GPU machine), one line per lattice size, drawn log-log: end-to-end seconds, the sampler's kernel seconds and the disk
baseline (dd writing the same bytes), and the peak resident memory against the budget."""

import glob
import json
import os

from . import plots
from .tables import Table, count, number


def load(results_dir):
    """{run id: [rows in file order]} of every scaling run under results_dir/scaling and
    results_dir/gpu/scaling; a line that is not JSON is reported by file and line."""
    runs = {}
    paths = glob.glob(os.path.join(results_dir, "scaling", "*", "scaling.jsonl")) + \
        glob.glob(os.path.join(results_dir, "gpu", "scaling", "*", "scaling.jsonl"))
    for path in sorted(paths, key=lambda p: os.path.basename(os.path.dirname(p))):
        rows = []
        with open(path) as f:
            for i, line in enumerate(f, 1):
                if not line.strip():
                    continue
                try:
                    rows.append(json.loads(line))
                except ValueError as e:
                    raise ValueError("%s:%d: not a JSON line (%s)" % (path, i, e))
        if rows:
            runs[os.path.basename(os.path.dirname(path))] = rows
    return runs


def _machine(row):
    m = row.get("machine", {})
    return "%s x%s, GPU %s" % (m.get("cpu", "?"), m.get("cpu_threads", "?"), m.get("gpu") or "none")


def _table(rows):
    table = Table(["points", "backend", "slabs", "end to end (s)", "kernels (s)", "disk baseline (s)",
                   "end to end / disk", "peak RSS (MiB)", "budget (MiB)", "output (MiB)"])
    for r in rows:
        disk = r["disk_baseline_seconds"]
        table.add([count(r["points"]), r["backend"], str(r["slabs"]), number(r["seconds"]), number(r["kernel_seconds"]),
                   number(disk), number(r["seconds"] / disk) if disk > 0 else "n/a",
                   number(r["peak_resident_bytes"] / 2**20), number(r["memory_budget_bytes"] / 2**20),
                   number(r["output_bytes"] / 2**20)])
    return table


def section(doc, results_dir):
    runs = load(results_dir)
    doc.heading(2, "Time and memory against lattice size (streamed sampling)")
    if not runs:
        doc.note("No scaling run in the results: run `scripts/scaling-run MESH` (docs/large-lattices.md).")
        return
    for run_id, rows in runs.items():
        first = rows[0]
        doc.heading(3, "%s, %s %s, run %s: %s" % (os.path.basename(first["mesh"]), first["lattice"].upper(),
                                                  "+".join(first["channels"]), run_id, _machine(first)))
        doc.table(_table(rows))
        xs = [r["points"] for r in rows]
        time_curves = [plots.Curve("end to end (sdf-sample)", xs, [r["seconds"] for r in rows]),
                       plots.Curve("sampler kernels", xs, [max(r["kernel_seconds"], 1e-6) for r in rows]),
                       plots.Curve("disk baseline (dd, same bytes)", xs, [max(r["disk_baseline_seconds"], 1e-6) for r in rows],
                                   dashed=True)]
        name = "scaling_time_%s.png" % run_id.replace(":", "")
        plots.log_log(os.path.join(doc.out_dir, name), "%s: time against lattice size" % run_id, "lattice points",
                      "seconds", time_curves)
        doc.image(name, "Run %s: seconds against lattice points (log-log)" % run_id)
        memory_curves = [plots.Curve("peak resident memory", xs, [r["peak_resident_bytes"] / 2**20 for r in rows]),
                         plots.Curve("memory budget", xs, [r["memory_budget_bytes"] / 2**20 for r in rows], dashed=True),
                         plots.Curve("output size", xs, [r["output_bytes"] / 2**20 for r in rows], dashed=True)]
        name = "scaling_memory_%s.png" % run_id.replace(":", "")
        plots.log_log(os.path.join(doc.out_dir, name), "%s: memory against lattice size" % run_id, "lattice points",
                      "MiB", memory_curves)
        doc.image(name, "Run %s: peak host memory, budget and output size against lattice points (log-log)" % run_id)
