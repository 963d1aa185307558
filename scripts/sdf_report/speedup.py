"""Thesis Tables 3-1 (meshes) and 3-2 (sampling times and speedups) from "speedup" runs; the
thesis's figures come from the metrics (experiments/common/thesis_tables.h writes them)."""

import os

from . import plots
from .schema import lattice_types
from .overview import machine
from .tables import Table, count, number, rate


def backend_names(metrics):
    names = []
    for row in metrics["rows"]:
        for b in row["backends"]:
            if b["name"] not in names:
                names.append(b["name"])
    return names


def meshes_table(runs):
    table = Table(["mesh", "source", "triangles", "vertices", "thesis triangles", "thesis vertices"])
    seen = set()
    for run in runs:
        for label, mesh in sorted(run.metrics["meshes"].items()):
            key = (label, mesh["sha256"])
            if key in seen:
                continue
            seen.add(key)
            thesis = mesh.get("thesis_table_3_1")
            table.add([label, os.path.basename(mesh["source"]), count(mesh["triangles"]), count(mesh["vertices"]),
                       count(thesis["triangles"]) if thesis else "-", count(thesis["vertices"]) if thesis else "-"])
    return table


def _time(backend):
    if backend["status"] != "ok":
        return "n/a"
    return number(backend["total_seconds_median"]) + ("*" if backend["extrapolated"] else "")


def times_table(metrics):
    names = backend_names(metrics)
    reference = metrics["reference"]
    others = [n for n in names if n != reference]
    table = Table(["mesh", "samples", "lattice", "points"] + ["%s (s)" % n for n in names] +
                  ["speedup %s" % n for n in others] + ["thesis GPU (s)", "thesis CPU (s)", "thesis speedup"])
    for row in metrics["rows"]:
        by = {b["name"]: b for b in row["backends"]}
        times = [_time(by[n]) if n in by else "-" for n in names]
        speedups = [number(by[n]["speedup_vs_reference"]) if n in by and "speedup_vs_reference" in by[n] else "n/a"
                    for n in others]
        thesis = row.get("thesis")
        thesis_cells = [number(thesis["gpu_seconds"]), number(thesis["cpu_seconds"]), "%.0f" % thesis["speedup"]] \
            if thesis else ["-", "-", "-"]
        table.add([row["mesh"], count(row["samples_requested"]), "%s %s" % (row["lattice"], row["resolution"]),
                   count(row["points"])] + times + speedups + thesis_cells)
    return table


def throughput_table(metrics):
    names = backend_names(metrics)
    table = Table(["mesh", "lattice", "points", "triangles"] + ["%s pairs/s" % n for n in names])
    for row in metrics["rows"]:
        by = {b["name"]: b for b in row["backends"]}
        table.add([row["mesh"], "%s %s" % (row["lattice"], row["resolution"]), count(row["points"]), count(row["triangles"])] +
                  [rate(by[n]["pairs_per_second"]) if n in by and by[n]["status"] == "ok" else "n/a" for n in names])
    return table


def reference_is_one_cpu_thread(metrics):
    """The thesis's speedups are against one CPU core: comparable only when ours are too."""
    return any(b["name"] == metrics["reference"] and b["sampler"]["backend"] == "cpu" and b["sampler"]["threads"] == 1
               for row in metrics["rows"] for b in row["backends"])


def speedup_plot(doc, run):
    metrics = run.metrics
    reference = metrics["reference"]
    cartesian = lattice_types()[0]  # the thesis's speedup figures are of CC lattices
    curves = []
    for mesh in sorted({row["mesh"] for row in metrics["rows"]}):
        for name in backend_names(metrics):
            if name == reference:
                continue
            pts = [(row["points"], b["speedup_vs_reference"]) for row in metrics["rows"]
                   if row["mesh"] == mesh and row["lattice"] == cartesian for b in row["backends"]
                   if b["name"] == name and "speedup_vs_reference" in b]
            if pts:
                curves.append(plots.Curve("%s %s" % (mesh, name), [p[0] for p in pts], [p[1] for p in pts]))
    if not curves:
        return
    thesis = sorted({(row["samples_requested"], row["thesis"]["speedup"]) for row in metrics["rows"] if "thesis" in row})
    markers = None
    if thesis and reference_is_one_cpu_thread(metrics):
        markers = ("thesis (GTX 465 vs 1 core)", [t[0] for t in thesis], [t[1] for t in thesis])
    filename = "speedup_vs_size_%s.png" % run.name
    plots.log_log(os.path.join(doc.out_dir, filename), "%s: speedup vs lattice size (CC rows)" % run.name,
                  "lattice points (CC)", "speedup vs %s" % reference, curves, markers)
    doc.image(filename, "%s: speedup versus lattice size (CC rows)" % run.name)


def section(doc, runs):
    speedup_runs = [r for r in runs if r.kind == "speedup"]
    doc.heading(2, "Table 3-1: meshes")
    if not speedup_runs:
        doc.note("No speedup run in the results: run `run-experiment configs/speedup.json`.")
    else:
        doc.table(meshes_table(speedup_runs))
        thesis_dragons = {"photon-dragon.obj", "dragon-legacy.obj"}  # the published file and its older local copy
        used = {os.path.basename(m["source"]) for r in speedup_runs for m in r.metrics["meshes"].values()}
        for name in sorted(used & thesis_dragons):
            doc.paragraph(f"{name} is the mesh with the thesis's exact counts (it has 25 self-intersecting "
                          "triangle pairs); the error studies use Stanford's published decimation "
                          "dragon_vrip_res2.ply.gz (202,520 triangles, with holes, winding sign).")
    doc.heading(2, "Table 3-2: sampling times and speedups")
    if not speedup_runs:
        doc.note("No speedup run in the results.")
        return
    for run in speedup_runs:
        metrics = run.metrics
        cpu, gpu = machine(run)
        doc.heading(3, "%s: %s, GPU %s" % (run.name, cpu, gpu))
        if run.manifest["description"]:
            doc.paragraph(run.manifest["description"])
        doc.table(times_table(metrics))
        reference = metrics["reference"]
        text = ("Median end-to-end times over the repetitions (transfers included); * = timed on a strided subset of "
                "the lattice and scaled to all points. Speedups are ratios of medians measured in the same run, relative "
                "to %s. n/a = backend unavailable on the machine of the run. Thesis: GeForce GTX 465 against one CPU "
                "core." % reference)
        if not reference_is_one_cpu_thread(metrics):
            text += (" This run's reference is not one CPU thread, so its speedups are not comparable with the "
                     "thesis's.")
        doc.paragraph(text)
        doc.table(throughput_table(metrics))
        doc.paragraph("Throughput: point-triangle pairs per second of the computation alone (median), per backend.")
        speedup_plot(doc, run)
