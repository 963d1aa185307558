"""Reconstruction studies (thesis Figures 5-2..5-11) from "reconstruction" runs: per mesh (and
sweep point) the errors of every reconstruction at the probes, an error-versus-samples plot
for sweeps, and the thesis's image grids with their image metrics."""

import os

from . import images, plots
from .analytic import eval_cost
from .schema import lattice_types
from .tables import Table, count, distinct_functions, number, percent, reconstruction_label, same_function_as

ERROR_HEADER = ["reconstruction", "thesis panel", "RMS / h", "max / h", "band mean / h", "band RMS / h",
                "angle mean (deg)", "angle p95 (deg)", "eval (ns/point)"]


def error_table(metrics):
    h = metrics["probes"]["h_ref"]
    table = Table(ERROR_HEADER)
    for rec in metrics["reconstructions"]:
        e = rec["errors"]
        table.add([reconstruction_label(rec["interpolator"], rec["derivatives"], rec["lattice"] + "/"),
                   rec["thesis_panel"] or "-", number(e["domain"]["rms"] / h), number(e["max_abs"] / h),
                   number(e["band"]["mean_abs"] / h), number(e["band"]["rms"] / h),
                   number(e["band"]["gradient_angle_mean_deg"], 3), number(e["band"]["gradient_angle_p95_deg"], 3),
                   eval_cost(rec)])
    return table


def study_summary(metrics):
    mesh = metrics["mesh"]
    probes = metrics["probes"]
    def lattice_text(l):
        name = l["label"] if l["lattice"]["notation"] in l["label"] else "%s %s" % (l["label"], l["lattice"]["notation"])
        return "%s (%s points%s)" % (name, count(l["lattice"]["points"]), ", from the cache" if l["from_cache"] else "")
    lattices = ", ".join(lattice_text(l) for l in metrics["lattices"])
    return ("Mesh %s (%s, %s triangles); %s; h = %s; %s domain probes, %s in the band w = %s h."
            % (mesh["name"], os.path.basename(mesh["source"]), count(mesh["triangles"]), lattices,
               number(probes["h_ref"]), count(probes["domain"]), count(probes["in_band"]), number(probes["band_spacings"])))


def sweep_plot(doc, run):
    curves, kind_of = {}, {}
    for point in run.points:
        lattices = point.metrics["lattices"]
        mean_points = sum(l["lattice"]["points"] for l in lattices) / len(lattices)
        type_of_label = {l["label"]: l["lattice"]["type"] for l in lattices}
        for rec in point.metrics["reconstructions"]:
            key = (rec["interpolator"], rec["derivatives"])
            curves.setdefault(key, []).append((mean_points, rec["errors"]["band"]["rms"]))
            kind_of[key] = type_of_label.get(rec["lattice"])
    cartesian = lattice_types()[0]  # solid; every other kind dashed
    lines = [plots.Curve(label, [v[0] for v in curves[key]], [v[1] for v in curves[key]], dashed=kind_of[key] != cartesian)
             for key, label in distinct_functions(sorted(curves))]
    filename = "%s_error_vs_samples.png" % run.name
    plots.log_log(os.path.join(doc.out_dir, filename), "%s: error vs samples (solid CC, dashed BCC)" % run.name,
                  "lattice points (mean of CC and BCC)", "band RMS error (mesh units)", lines)
    doc.image(filename, "%s: band RMS error versus samples" % run.name)


def studies_section(doc, runs):
    doc.heading(2, "Reconstruction errors per mesh and interpolator")
    if not runs:
        doc.note("No reconstruction run in the results: run `run-experiment configs/dragon.json` (and bunny, "
                 "soccer_ball, buddha, pawn_sweep).")
        return
    doc.paragraph("Errors against the exact signed distance at random probes: RMS and max over the domain every "
                  "reconstruction covers, mean and RMS of |error| in the band |d| <= w around the surface, and the angle "
                  "between reconstructed and exact gradients in the band. Lengths are in units of h, the coarsest "
                  "lattice spacing of the study. Thesis panel: the panel (A..E) of the thesis's figures the "
                  "reconstruction stands for. tricubic_lm with central-difference derivatives (fd) is the same function "
                  "as Catmull-Rom (docs/reconstruction.md), so their rows agree to rounding.")
    for run in runs:
        points = run.points
        figures = points[0].metrics["thesis_figures"]
        doc.heading(3, "%s%s" % (run.name, " (thesis Figures %s)" % ", ".join(figures) if figures else ""))
        if run.manifest["description"]:
            doc.paragraph(run.manifest["description"])
        for point in points:
            if run.is_sweep:
                doc.heading(4, point.name)
            doc.paragraph(study_summary(point.metrics))
            doc.table(error_table(point.metrics))
        if run.is_sweep:
            sweep_plot(doc, run)


# ---- image grids -------------------------------------------------------------------------------------

def panel_label(panel, panels):
    """The panel's label without its letter ("Catmull-Rom (80x80x80)"), marked when it shows
    the same function as another panel."""
    label = panel["label"]
    if label.startswith(panel["letter"] + " "):
        label = label[len(panel["letter"]):].strip()
    interpolator, _, derivatives = panel["render"]["reconstruction"].partition("/")
    twin = same_function_as(interpolator, derivatives)
    if twin:
        for other in panels:
            if other["render"]["reconstruction"] == "%s/%s" % twin:
                # Grids made since issue 13 mark it briefly themselves, "(= A)": said once, in full.
                label = label.replace(" (= %s)" % other["letter"], "")
                return "%s (= %s: same function)" % (label, other["letter"])
    return label


def image_metrics_table(view):
    table = Table(["panel", "reconstruction", "normal mean (deg)", "normal p95 (deg)", "depth mean (h)",
                   "coverage mismatch", "shade RMSE", "render (s)"])
    for panel in view["panels"]:
        m = panel.get("metrics")
        if not m:
            continue
        depth = m.get("depth_in_length_units", m["depth_world"])
        table.add([panel["letter"], panel_label(panel, view["panels"]), number(m["normal_angle_degrees"]["mean"], 3),
                   number(m["normal_angle_degrees"]["p95"], 3), number(depth["mean"], 3),
                   percent(m["coverage_mismatch_fraction"]), number(m["shade_rmse"], 3),
                   number(panel["render"]["seconds"], 3)])
    return table


def grids(runs):
    """(point, view name, view, grid image path) of every rendered grid whose image exists."""
    found = []
    for run in runs:
        for point in run.points:
            for name, view in sorted(point.metrics.get("render", {"views": {}})["views"].items()):
                path = os.path.join(point.dir, view["grid_file"])
                found.append((point, name, view, path))
    return found


def grids_section(doc, runs):
    doc.heading(2, "Image grids (thesis Figures 5-2..5-11)")
    doc.paragraph("Each grid is laid out as the thesis's figures: A Catmull-Rom (CC), B BCC cubic with true derivatives, "
                  "C BCC cubic with estimated derivatives; D CC tricubic with true, E with estimated derivatives (E is "
                  "the same function as A); then the mesh itself (ray-traced) and the normal-error heat maps of A..E "
                  "against it. Image metrics are against that reference. A study whose \"render\" block lists "
                  "\"panels\" shows those reconstructions instead, lettered in its order (e.g. the thesis's five "
                  "and then the prefiltered splines).")
    found = grids(runs)
    if not found:
        doc.note("No rendered grids in these results (the studies' \"render\" block renders them).")
        return
    scales = {}
    for point, name, view, path in found:
        doc.heading(3, "%s, view %s" % (point.name, name))
        if os.path.isfile(path):
            target = "grid_%s_%s.png" % (point.name, name)
            images.write_reduced_grid(path, os.path.join(doc.out_dir, target))
            doc.image(target, "%s, view %s" % (point.name, name))
            if any("metrics" in p for p in view["panels"]):  # the grid has heat maps: their scale
                scale = view["grid"]["heat_max_degrees"]
                if scale not in scales:
                    scales[scale] = "heat_map_scale_%g.png" % scale
                    plots.heat_map_colour_bar(os.path.join(doc.out_dir, scales[scale]), scale)
                doc.image(scales[scale], "Colour scale of the heat maps above (0 to %g degrees)" % scale)
        else:
            doc.note("The grid image %s is missing (the run's images were not kept)." % path)
        table = image_metrics_table(view)
        if table:
            doc.table(table)


def thesis_order(run):
    """Sort key: the run's first thesis figure ("5-2" < "5-3" < ... < "5-11"), then its name;
    studies standing for no figure come last."""
    figures = run.points[0].metrics["thesis_figures"]
    if figures and all(part.isdigit() for part in figures[0].split("-")):
        return (0, tuple(int(part) for part in figures[0].split("-")), run.name)
    return (1, (), run.name)


def section(doc, runs):
    reconstruction_runs = sorted((r for r in runs if r.kind == "reconstruction"), key=thesis_order)
    studies_section(doc, reconstruction_runs)
    grids_section(doc, reconstruction_runs)
