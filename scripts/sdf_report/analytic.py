"""Thesis Table 4-1 (Marschner-Lobb, plain vs Gaussian-weighted least squares) and error
versus sample count of analytic functions, from "analytic" runs. The thesis's Table 4-1
figures come from the metrics (experiments/common/thesis_tables.h writes them)."""

import os

from . import plots
from .schema import lattice_types
from .tables import Table, count, distinct_functions, number, reconstruction_label, split_curve_id


def table_4_1(t):
    thesis = t["thesis"]
    table = Table(["derivatives", "RMS", "max abs error", "RMS x 255", "L2 x 255",
                   "thesis %s (\"L2 norm error\")" % thesis["dataset"]])
    for which in ("plain", "weighted"):
        s = t[which]
        table.add([which, number(s["rms"]), number(s["max_abs"]), number(s["rms_255"]), number(s["l2_norm_255"]),
                   number(thesis[which])])
    table.add(["weighted / plain", number(t["ratio_rms"]), "", "", "", number(thesis["ratio"])])
    return table


def eval_cost(entry):
    """One thread's time per evaluation as the harness measured it; n/a in runs before it did."""
    return number(entry["eval_ns_per_point"], 3) if "eval_ns_per_point" in entry else "n/a"


def convergence_table(c):
    table = Table(["reconstruction", "lattice", "points", "RMS", "max abs error", "gradient RMS", "eval (ns/point)"])
    for curve in c["curves"]:
        label = reconstruction_label(*split_curve_id(curve["id"]))
        for p in curve["points"]:
            table.add([label, p["lattice"], count(p["lattice_points"]), number(p["rms"]), number(p["max_abs"]),
                       number(p["gradient_rms"]), eval_cost(p)])
    return table


def convergence_plot(doc, point, c):
    by_key = {split_curve_id(curve["id"]): curve for curve in c["curves"]}
    cartesian = lattice_types()[0]  # solid; every other kind dashed
    curves = [plots.Curve(label, [p["lattice_points"] for p in by_key[key]["points"]],
                          [p["rms"] for p in by_key[key]["points"]], dashed=by_key[key]["lattice_type"] != cartesian)
              for key, label in distinct_functions(by_key)]
    filename = "%s_error_vs_samples.png" % point.name
    plots.log_log(os.path.join(doc.out_dir, filename), "%s: error vs samples (solid CC, dashed BCC)" % c["function"],
                  "lattice points", "RMS error", curves)
    doc.image(filename, "%s: RMS error versus sample count, %s" % (point.name, c["function"]))


def section(doc, runs):
    analytic = [r for r in runs if r.kind == "analytic"]
    doc.heading(2, "Table 4-1: Marschner-Lobb, plain vs Gaussian-weighted least squares")
    with_table = [p for r in analytic for p in r.points if "table_4_1" in p.metrics]
    if not with_table:
        doc.note("No analytic run with \"table_4_1\" in the results: run `run-experiment configs/ml.json`.")
    for run in analytic:
        for point in run.points:
            if "table_4_1" not in point.metrics:
                continue
            t = point.metrics["table_4_1"]
            doc.table(table_4_1(t))
            doc.paragraph("%s: %s on a %s BCC lattice over [-1,1]^3, bcc_cubic, sigma^2 = %s (sigma in %s), probes %s "
                          "spacings inside the lattice. The thesis does not define its norm; the ratio weighted / plain is "
                          "the comparable figure." % (point.name, t["function"], t["lattice"], number(t["sigma2"]),
                                                      t["sigma_units"], number(t["margin_spacings"])))
    doc.heading(2, "Error versus sample count (analytic function)")
    with_curves = [p for r in analytic for p in r.points if "convergence" in p.metrics]
    if not with_curves:
        doc.note("No analytic run with \"convergence\" in the results.")
    for point in with_curves:
        c = point.metrics["convergence"]
        doc.table(convergence_table(c))
        convergence_plot(doc, point, c)
