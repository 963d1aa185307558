"""Where the user waits (issue 23): the runs of scripts/user-wait, results/user_wait/<run-id>/
user_wait.json (local) or results/gpu/user_wait/<run-id>/user_wait.json (committed runs of the
GPU machine). Per machine the latest run: a table of every row (wall time beside kernel time,
the peer of the same run where the row has one, or why the row did not run), the Python
one-liner against its peers on the same points (issue 24), and one plot of wall time against
kernel time of every measured row of every machine."""

import glob
import json
import os

from . import plots
from .tables import Table, count, number

FORMAT = "sdf-user-wait"
# Keys every run and every measured row must have, with their types (a file that lacks one
# is an error naming the file and the key, never a blank cell).
RUN_KEYS = {"run_id": str, "started": str, "machine": dict, "commit": str, "rows": list}
MEASURED_KEYS = {"id": str, "title": str, "wall_seconds": (int, float), "kernel_what": str}


HEADING = "Where the user waits (wall time beside kernel time)"


class UserWaitFileError(ValueError):
    pass


def _check(obj, keys, where):
    for key, types in keys.items():
        if key not in obj:
            raise UserWaitFileError("%s: key '%s': missing" % (where, key))
        if not isinstance(obj[key], types) or isinstance(obj[key], bool):
            raise UserWaitFileError("%s: key '%s': expected %s, got %r" % (where, key, types, obj[key]))


def read_run(path):
    try:
        with open(path) as f:
            run = json.load(f)
    except (OSError, ValueError) as e:
        raise UserWaitFileError("%s: cannot read it as JSON: %s" % (path, e)) from None
    if not isinstance(run, dict) or run.get("format") != FORMAT or run.get("version") != 1:
        raise UserWaitFileError("%s: key 'format': expected \"%s\", version 1 (scripts/user-wait)" % (path, FORMAT))
    _check(run, RUN_KEYS, path)
    for i, row in enumerate(run["rows"]):
        where = "%s: rows[%d]" % (path, i)
        if row.get("status") == "measured":
            _check(row, MEASURED_KEYS, where)
            if row.get("kernel_seconds") is not None and not isinstance(row["kernel_seconds"], (int, float)):
                raise UserWaitFileError("%s: key 'kernel_seconds': expected a number or null" % where)
        else:
            _check(row, {"id": str, "status": str, "reason": str}, where)
    return run


def is_user_wait_file(path):
    """Whether path is a scripts/user-wait record (a .json file whose "format" says so)."""
    if not (os.path.isfile(path) and path.endswith(".json")):
        return False
    try:
        with open(path) as f:
            data = json.load(f)
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and data.get("format") == FORMAT


def load(results_dir, files=None):
    """The latest run per machine (CPU model, threads, GPU), in order of start: of `files`
    when given (user_wait.json paths), else of every run under results_dir/user_wait and
    results_dir/gpu/user_wait."""
    paths = files or glob.glob(os.path.join(results_dir, "user_wait", "*", "user_wait.json")) + \
        glob.glob(os.path.join(results_dir, "gpu", "user_wait", "*", "user_wait.json"))
    latest = {}
    for path in paths:
        run = read_run(path)
        m = run["machine"]
        key = (m.get("cpu"), m.get("cpu_threads"), m.get("gpu"))
        if key not in latest or run["started"] > latest[key]["started"]:
            latest[key] = run
    return sorted(latest.values(), key=lambda r: r["started"])


def machine_text(run):
    m = run["machine"]
    return "%s x%s, GPU %s" % (m.get("cpu", "?"), m.get("cpu_threads", "?"), m.get("gpu") or "none")


def _peer_text(row):
    peer = row.get("peer")
    if not peer:
        return "-", "-"
    build, query = peer.get("build_seconds", 0.0), peer["query_seconds"]
    ours = row["details"]["ours"]
    our_total = ours.get("build_seconds", 0.0) + ours["query_seconds"]
    text = "%s: build %s + query %s" % (peer["name"], number(build), number(query))
    return text, "query %s, build + query %s" % (number(ours["query_seconds"] / query) if query > 0 else "n/a",
                                                  number(our_total / (build + query)) if build + query > 0 else "n/a")


# Details a row may record, each shown in the notes with its label and unit (one table).
NOTES = [("seconds", "the tool's own end to end", "s"), ("disk_baseline_seconds", "dd writing the same bytes", "s"),
         ("peak_resident_bytes", "peak RSS", "MiB"), ("load_mesh_seconds", "mesh load (Python, alone)", "s"),
         ("build_seconds", "SDF build", "s"), ("query_without_built_sdf_seconds", "sl.query, building for the call", "s"),
         ("sampling_seconds", "sampling end to end", "s"), ("render_seconds", "ray cast", "s"),
         ("backend", "backend", ""), ("sign", "sign", "")]


def _notes(row):
    details = row.get("details", {})
    parts = []
    for key, label, unit in NOTES:
        value = details.get(key)
        if value is None:
            continue
        if unit == "MiB":
            parts.append("%s %s MiB" % (label, number(value / 2**20)))
        elif unit:
            parts.append("%s %s %s" % (label, number(value), unit))
        else:
            parts.append("%s %s" % (label, value))
    return "; ".join(parts) or "-"


def rows_table(run):
    table = Table(["row", "what the user runs", "kernel or compute (s)", "what the user waits (s)", "wall / kernel",
                   "the kernel time is", "peer, same run (s)", "ours / peer (time; below 1: ours faster)", "notes"])
    for row in run["rows"]:
        if row["status"] != "measured":
            table.add([row["id"], "%s: %s" % (row["status"], row["reason"]), "-", "-", "-", "-", "-", "-", "-"])
            continue
        kernel = row.get("kernel_seconds")
        ratio = number(row["wall_seconds"] / kernel) if kernel else "n/a"
        peer, versus = _peer_text(row)
        table.add([row["id"], row["title"], number(kernel), number(row["wall_seconds"]), ratio, row["kernel_what"],
                   peer, versus, _notes(row)])
    return table


def one_liner_table(record):
    table = Table(["method", "build (s)", "query (s)", "total (s)", "points/s", "max |error|", "max error of |d|",
                   "median |error|", "wrong sign", "note"])
    points = record["points"]
    for r in record["rows"]:
        table.add([r["method"], number(r["build_seconds"]), number(r["query_seconds"]), number(r["total_seconds"]),
                   "%.3g" % (points / r["total_seconds"]) if r["total_seconds"] > 0 else "n/a",
                   number(r.get("max_abs_error")), number(r.get("max_abs_error_unsigned")), number(r.get("median_abs_error")),
                   "%.3f%%" % (100 * r["wrong_sign_fraction"]) if "wrong_sign_fraction" in r else "-", r["note"]])
    for r in record.get("not_run", []):
        table.add([r["method"], "-", "-", "-", "-", "-", "-", "-", "-", "not run: " + r["reason"]])
    return table


def _plot(doc, runs):
    series = []
    for run in runs:
        points = [(r["id"], r["kernel_seconds"], r["wall_seconds"]) for r in run["rows"]
                  if r["status"] == "measured" and r.get("kernel_seconds") and r["wall_seconds"] > 0]
        if points:
            series.append((machine_text(run), points))
    if not series:
        return
    name = "user_wait_wall_vs_kernel.png"
    plots.wall_against_kernel(os.path.join(doc.out_dir, name), "Where the user waits: wall time against kernel time",
                              series)
    doc.image(name, "Wall time against kernel (or compute) time of every measured row, one marker per machine "
                    "(log-log; rows without a kernel time are left out). On the line the user waits only for the "
                    "computation; the distance above it is the time spent elsewhere (loading, building, transfers, "
                    "conversion, writing).")


def section(doc, results_dir, files=None):
    runs = load(results_dir, files)
    doc.heading(2, HEADING)
    if not runs:
        doc.note("No user-wait run in the results: run `scripts/user-wait` (issue 23's table, measured as a user runs it).")
        return
    doc.paragraph("Each row of issue 23's table measured as a user runs it (scripts/user-wait): the wall time of the "
                  "process or Python call beside the kernel (or compute) time the tool reports for the same call, and "
                  "the peer of the same run where the row compares with one. The issue's horse and 13k-triangle CAD "
                  "model are not among the project's meshes: the experiment row samples dragon-legacy.obj (100,000 triangles), "
                  "the render row a generated 13,000-triangle CAD-like box (each planar face a fan from its centre "
                  "over its split edges, as the project's CAD test models: a hard case for the BVH, since every "
                  "triangle of a face reaches its centre). Rows the machine cannot run (no GPU, a peer "
                  "not built) say so. The latest run per machine.")
    for run in runs:
        doc.heading(3, "Run %s: %s" % (run["run_id"], machine_text(run)))
        load_text = ""
        if "load_start" in run and "load_end" in run:
            load_text = "; load average %s at the start, %s at the end" % (number(run["load_start"][0]), number(run["load_end"][0]))
        doc.paragraph("Commit %s, build %s%s." % (run["commit"][:16], os.path.basename(run.get("build", "?")), load_text))
        threads = run["machine"].get("cpu_threads") or 0
        if threads and max(run.get("load_start", [0])[0], run.get("load_end", [0])[0]) > threads:
            doc.note("Made on a loaded machine (load above its %d hardware threads): the times are inflated by other "
                     "work, and only the same run's numbers compare." % threads)
        doc.table(rows_table(run))
        record = run.get("one_liner")
        if record and record.get("status") == "measured":
            doc.paragraph("The Python one-liner against its peers on the same %s points (half uniform in the box grown "
                          "by 10%%, half Gaussian around the surface, sigma 1%%), dragon.obj normalised to the unit cube "
                          "(%s triangles), ours on %s, sign %s; errors against our exact values (max |error| counts a wrong sign; "
                          "max error of |d| does not):"
                          % (count(record["points"]), count(record["triangles"]), record["sampler"], record["sign"]))
            doc.table(one_liner_table(record))
        elif record:
            doc.note("The one-liner against its peers: %s: %s" % (record["status"], record.get("reason", "")))
    _plot(doc, runs)
