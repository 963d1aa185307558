"""Our samplers (brute force and BVH, CPU and GPU) against the peer libraries (CGAL, Embree,
Open3D, OpenVDB, FCPW, cuBQL), on lattices and on arbitrary point sets, from "peers" runs
(configs/peers.json, configs/peers_gpu.json, docs/bvh-peers.md); and narrow bands (level sets): our
sparse band against OpenVDB's meshToLevelSet and NanoVDB's MeshToGrid (configs/peers_band.json)."""

from .overview import machine
from .tables import Table, count, number, rate

HEADER = ["mesh, points", "method", "by", "threads", "sign", "build (s)", "query (s)", "CPU (s)", "points/s", "max |d error|",
          "sign disagreements", "passes check", "notes"]


def sign_label(row):
    """The row's sign: pseudonormal, winding, unsigned, or the peer's own rule (as the
    experiment's sign_label, experiments/peers/peer_rows.cpp); runs from before "sign" was
    recorded: signed or unsigned."""
    sign = row.get("sign")
    if sign is None:
        if "signed" in row:
            return "signed" if row["signed"] else "unsigned"
        return "unsigned" if isinstance(row.get("sign_disagreements"), str) else "signed"
    if sign == "none":
        return "unsigned"
    if sign == "own":
        return "own: " + row.get("sign_method", "?")
    return sign


def _check(row):
    """The row's check (runs before it was recorded: '-')."""
    if "passes_check" not in row:
        return "-"
    if row["passes_check"]:
        return "yes" if row.get("signed", True) else "yes (unsigned)"
    return "no: " + row.get("check", "?")


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
        if _is_band_row(row):
            continue
        where = "%s %s" % (row["mesh"], row["resolution"])
        method = row["method"] + (" " + row["version"] if "version" in row else "")
        if "status" in row:
            table.add([where, method, row["by"], "-", "-", "-", "-", "-", "-", "-", "-", "-", row["status"]])
            continue
        table.add([where, method, row["by"], str(row["threads"]), sign_label(row), number(row["build_seconds"]),
                   number(row["query_seconds"]), number(row["cpu_seconds"]) if "cpu_seconds" in row else "-",
                   rate(row["points_per_second"]), number(row["max_abs_error"]), str(row["sign_disagreements"]),
                   _check(row), _notes(row)])
    return table


BAND_HEADER = ["mesh, lattice, band", "method", "by", "threads", "sign", "build (s)", "band (s)", "total (s)", "CPU (s)",
               "end to end (s)", "active voxels", "max |d error| (active voxels)", "wrong signs", "notes"]


def _is_band_row(row):
    """A narrow-band row (band_resolutions): its level set, or a band method's status row."""
    return "level_set" in row or " band " in row["resolution"]


def band_table(metrics):
    """Every method's own narrow band on the same lattice: time (build included), its active
    voxels, and its accuracy there against the exact field; unsigned rows have no wrong signs."""
    table = Table(BAND_HEADER)
    for row in metrics["rows"]:
        if not _is_band_row(row):
            continue
        where = "%s %s" % (row["mesh"], row["resolution"])
        method = row["method"] + (" " + row["version"] if "version" in row else "")
        if "status" in row:
            table.add([where, method, row["by"]] + ["-"] * 10 + [row["status"]])
            continue
        signed = row.get("signed", True)
        table.add([where, method, row["by"], str(row["threads"]), sign_label(row), number(row["build_seconds"]),
                   number(row["query_seconds"]), number(row["total_seconds"]),
                   number(row["cpu_seconds"]) if "cpu_seconds" in row else "-",
                   number(row["end_to_end_seconds"]) if "end_to_end_seconds" in row else "-",
                   count(row["active_voxels"]), number(row["max_abs_error"]),
                   str(row["sign_disagreements"]) if signed else "n/a (unsigned)",
                   "" if signed else "unsigned: the error is ||d| - |exact||"])
    return table


def _fastest(s, checked):
    """The fastest exact peer with its sign, or the older runs' notes (exactness not checked,
    unsigned)."""
    name = s["fastest_exact_peer"]
    if not checked:
        return name + " (exactness not checked: run before passes_check)"
    if "fastest_exact_peer_sign" in s:
        return "%s [%s]" % (name, s["fastest_exact_peer_sign"])
    if s.get("fastest_exact_peer_signed") is False:
        return name + " (unsigned: returns no sign)"
    return name


def _ours(s):
    """Our row of the comparison with its sign; older runs' summaries could rest on a row that
    failed its check, which is said."""
    ours = s.get("ours", "bvh_cpu")
    if "ours_sign" in s:
        ours += " [%s]" % s["ours_sign"]
    if s.get("ours_passes_check") is False:
        ours += " (fails check: %s)" % s.get("ours_check", "?")
    return ours


def _excluded(s):
    return "; ".join("%s [%s]: %s" % (e["method"], e["sign"], e["check"]) for e in s.get("excluded", [])) or "-"


def summary_table(metrics):
    """Our fastest row that passes its check against the fastest peer that passes (same points,
    same threads); where none of ours passes, no ratio (not_compared)."""
    checked = any("passes_check" in row for row in metrics["rows"])
    table = Table(["mesh, points", "threads", "ours", "fastest exact peer", "speedup (query)", "speedup (build + query)",
                   "CPU-time ratio", "goal", "fastest exact signed peer (query speedup)",
                   "our rows that fail their check (not compared)"])
    for s in metrics.get("summary", []):
        where = "%s %s" % (s["mesh"], s["resolution"])
        if "not_compared" in s:
            table.add([where, str(s["threads"]), "-", "not compared: " + s["not_compared"], "-", "-", "-", number(s["goal"]),
                       "-", _excluded(s)])
            continue
        signed = "-"
        if "fastest_exact_signed_peer" in s:
            peer = s["fastest_exact_signed_peer"]
            if "fastest_exact_signed_peer_sign" in s:
                peer += " [%s]" % s["fastest_exact_signed_peer_sign"]
            signed = "%s (%s)" % (peer, number(s["query_speedup_vs_signed"]))
        table.add([where, str(s["threads"]), _ours(s), _fastest(s, checked),
                   number(s["query_speedup"]) + (" (end to end)" if s.get("compared_time") == "end_to_end_seconds" else ""),
                   number(s["total_speedup"]),
                   number(s["cpu_time_ratio"]) if "cpu_time_ratio" in s else "-", number(s["goal"]), signed, _excluded(s)])
    return table


HEADING = "Exact sampling against the peer libraries (BVH)"


def section(doc, runs):
    peers_runs = [r for r in runs if r.kind == "peers"]
    doc.heading(2, HEADING)
    if not peers_runs:
        doc.note("No peers run in the results: run `run-experiment configs/peers.json` (docs/bvh-peers.md).")
        return
    for run in peers_runs:
        for point in run.points:
            cpu, gpu = machine(run)
            doc.heading(3, "%s, run %s: %s, GPU %s" % (point.name, run.run_id, cpu, gpu))
            doc.table(rows_table(point.metrics))
            bands = band_table(point.metrics)
            if bands:
                doc.paragraph("Narrow bands (level sets) on the same lattice and band, on this machine (%s, GPU %s): each "
                              "method's own active voxels, its time with its build, and its accuracy there against the "
                              "exact field." % (cpu, gpu))
                doc.table(bands)
            summary = summary_table(point.metrics)
            if summary:
                doc.table(summary)
    doc.paragraph("Same machine, same run, same points: lattices (mesh, lattice) and arbitrary point sets (mesh, "
                  "uniform_box/N: uniform in the margin-expanded box; gaussian_surface(sigma)/N: area-weighted surface "
                  "points plus a Gaussian offset, sigma a fraction of the bounding-box diagonal). Errors are against our "
                  "exact field (the CPU BVH, equal to brute force; on point sets our CPU BVH query, checked against "
                  "the brute force on strided points). 'passes check' = max |d error| within the run's tolerance "
                  "(1e-5 x the bounding-box diagonal) and, for signed methods, no wrong sign farther than that from "
                  "the surface; unsigned peers pass as 'yes (unsigned)'. The summary compares only rows that pass their "
                  "checks (our rows that fail are listed beside it, never the basis of a ratio; runs before this rule "
                  "say 'fails check' where theirs was), and names every side's sign: pseudonormal, winding, unsigned, "
                  "or the peer's own rule. CPU (s) = process CPU time of build + query over all threads (robust to other load "
                  "on a shared machine). GPU rows are CUDA-event times of the query with the points on the device "
                  "(our point-set GPU rows: the device time of the Morton sort, search and finalize; 'end to end' = with "
                  "transfers); 'unavailable' = no GPU on the machine of the run; 'not built' = the peer's package or "
                  "source snapshot (FCPW, cuBQL: SDF_PEERS_DIR) was missing when the harness was built. OpenVDB is a "
                  "narrow-band method; Embree, FCPW and cuBQL return unsigned distances. See docs/bvh-peers.md.")
