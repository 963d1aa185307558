"""Our samplers (brute force and BVH, CPU and GPU) against the peer libraries (CGAL, Embree,
Open3D, OpenVDB), from "peers" runs (configs/peers.json, docs/bvh.md)."""

from .overview import machine
from .tables import Table, count, number, rate

HEADER = ["mesh, lattice", "method", "by", "threads", "build (s)", "query (s)", "CPU (s)", "points/s", "max |d error|",
          "sign disagreements", "notes"]


def _notes(row):
    band = row.get("band")
    if band:
        return "narrow band: max |d error| %s inside (%s points), %s outside" % (
            number(band["max_abs_error_in_band"]), count(band["points_in_band"]), number(band["max_abs_error_outside_band"]))
    if row.get("extrapolated"):
        return "timed on a strided subset, scaled to the lattice"
    if "end_to_end_seconds" in row:
        return "end to end %s s" % number(row["end_to_end_seconds"])
    return ""


def rows_table(metrics):
    table = Table(HEADER)
    for row in metrics["rows"]:
        where = "%s %s" % (row["mesh"], row["resolution"])
        method = row["method"] + (" " + row["version"] if "version" in row else "")
        if "status" in row:
            table.add([where, method, row["by"], "-", "-", "-", "-", "-", "-", "-", row["status"]])
            continue
        table.add([where, method, row["by"], str(row["threads"]), number(row["build_seconds"]),
                   number(row["query_seconds"]), number(row["cpu_seconds"]) if "cpu_seconds" in row else "-",
                   rate(row["points_per_second"]), number(row["max_abs_error"]), str(row["sign_disagreements"]),
                   _notes(row)])
    return table


def summary_table(metrics):
    table = Table(["mesh, lattice", "threads", "fastest exact peer", "BVH CPU speedup (query)",
                   "BVH CPU speedup (build + query)", "CPU-time ratio"])
    for s in metrics.get("summary", []):
        table.add(["%s %s" % (s["mesh"], s["resolution"]), str(s["threads"]), s["fastest_exact_peer"],
                   number(s["query_speedup"]), number(s["total_speedup"]), number(s["cpu_time_ratio"])])
    return table


def section(doc, runs):
    peers_runs = [r for r in runs if r.kind == "peers"]
    doc.heading(2, "Exact sampling against the peer libraries (BVH)")
    if not peers_runs:
        doc.note("No peers run in the results: run `run-experiment configs/peers.json` (docs/bvh.md).")
        return
    for run in peers_runs:
        for point in run.points:
            cpu, gpu = machine(run)
            doc.heading(3, "%s, run %s: %s, GPU %s" % (point.name, run.run_id, cpu, gpu))
            doc.table(rows_table(point.metrics))
            summary = summary_table(point.metrics)
            if summary:
                doc.table(summary)
    doc.paragraph("Same machine, same run, same lattice points. Errors are against our exact field (the CPU BVH, equal "
                  "to brute force). CPU (s) = process CPU time of build + query over all threads (robust to other load "
                  "on a shared machine). GPU rows are CUDA-event times; 'unavailable' = no GPU on the machine of the "
                  "run; 'not built' = the peer's package was missing when the harness was built. OpenVDB is a "
                  "narrow-band method; Embree returns unsigned distances. See docs/bvh.md.")
