"""Sampling times and throughput of every run that samples fields: the "sampling" kind's
fields and the "reconstruction" kind's lattices (one row per field). The "speedup" and
"peers" kinds time their samplers in their own sections."""

from .tables import Table, count, number, rate

KINDS = ("sampling", "reconstruction")


def _sampler_text(sampler):
    text = "%s/%s/%s" % (sampler["backend"], sampler["method"], sampler["kernel"])
    if "threads" in sampler:
        text += ", %d thread%s" % (sampler["threads"], "" if sampler["threads"] == 1 else "s")
    elif "device" in sampler and "name" in sampler["device"]:
        text += ", " + sampler["device"]["name"]
    return text + ", " + sampler["precision"]


def _fields(point, kind):
    """(label, obtained field) of a sampling or reconstruction run (point)."""
    if kind == "sampling":
        return [(f["name"], f) for f in point.metrics["fields"]]
    return [(f["label"], f) for f in point.metrics["lattices"]]


def rows(runs):
    table = Table(["run", "field", "lattice", "points", "triangles", "sampler", "time (s)", "computation (s)",
                   "pairs/s", "points/s", "source"])
    for run in runs:
        if run.kind not in KINDS:
            continue
        for point in run.points:
            triangles = point.metrics["mesh"]["triangles"]
            for label, f in _fields(point, run.kind):
                lattice = f["lattice"]
                kernel = f["kernel_seconds"]
                table.add([point.name, label, "%s %s" % (lattice["type"], lattice["notation"]), count(lattice["points"]),
                           count(triangles), _sampler_text(f["sampler"]), number(f["seconds"]), number(kernel),
                           rate(f["pairs_per_second"]), rate(lattice["points"] / kernel if kernel > 0 else 0.0),
                           "cache" if f["from_cache"] else "sampled"])
    return table


def section(doc, runs):
    doc.heading(2, "Sampling times and throughput")
    table = rows(runs)
    if not table:
        doc.note("No sampling or reconstruction run in the results: run e.g. `run-experiment configs/dragon_32k.json`.")
        return
    doc.table(table)
    doc.paragraph("One row per sampled field. Time: sampling end to end (for the GPU, transfers included); computation: "
                  "the distance search and evaluation alone; pairs/s: point-triangle pairs per second of the computation "
                  "(for BVH samplers the brute-force equivalent, points x triangles); points/s: lattice points per "
                  "second of the computation. Source \"cache\": the field came from the field cache and its times are "
                  "those of the run that sampled it, possibly on another machine. The speedup and peers sections below "
                  "time the samplers repeatedly, side by side.")
