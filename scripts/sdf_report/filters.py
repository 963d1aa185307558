"""Every filter of both lattices (issue 17): per study one table of the errors at matched
sample counts beside each filter's evaluation cost, the measured convergence orders, and the
test of the claim of Entezari, Van De Ville and Moeller (IEEE TVCG 14(2), 2008) that the BCC
quintic box spline is "twice as efficient" as the CC tricubic B-spline: the ratio of the
sample counts at which the two reach the same error, read off the measured curves.

From "analytic" runs (error versus samples, "convergence") and from "reconstruction" sweeps
(one point per pair of matched CC and BCC lattices). Orders are in h: e ~ h^p with the
samples ~ h^-3, so p = -3 d(log e) / d(log samples)."""

import math
import statistics

from .tables import Table, count, number, reconstruction_label, split_curve_id

# The pair the claim is about, and the other prefilters of the quintic shown beside it.
REFERENCE = ("cc_bspline3", "fd")
CANDIDATES = (("bcc_box_quintic", "fd"), ("bcc_box_quintic_qi", "fd"), ("bcc_box_quintic_approx", "fd"))
CLAIMED_RATIO = 2.0
# A measured ratio within 10% of the claim confirms it.
CONFIRMING_RATIO = 0.9 * CLAIMED_RATIO


# ---- curves --------------------------------------------------------------------------------------

def orders(series):
    """Orders between successive points of [(samples, error)] (sorted by samples)."""
    out = []
    for (n1, e1), (n2, e2) in zip(series, series[1:]):
        if e1 > 0 and e2 > 0 and n2 != n1:
            out.append(-3.0 * math.log(e2 / e1) / math.log(n2 / n1))
    return out


def samples_for_error(series, error):
    """Samples a series needs for `error`, by log-log interpolation between the two points
    that bracket it; None when the series never crosses it."""
    for (n1, e1), (n2, e2) in zip(series, series[1:]):
        if e1 <= 0 or e2 <= 0 or (e1 - error) * (e2 - error) > 0 or e1 == e2:
            continue
        t = math.log(error / e1) / math.log(e2 / e1)
        return math.exp(math.log(n1) + t * math.log(n2 / n1))
    return None


def efficiency_ratios(reference, candidate):
    """[(reference samples, reference error, candidate samples for that error, ratio)]:
    ratio > 1 means the candidate needs fewer samples for the same error."""
    rows = []
    for n, e in reference:
        m = samples_for_error(candidate, e)
        rows.append((n, e, m, n / m if m else None))
    return rows


def verdict(ratios, what):
    """One sentence on the claim from the measured ratios (None entries: out of range)."""
    measured = [r for r in ratios if r is not None]
    if not measured:
        return ("%s: the BCC quintic's errors do not overlap the CC B-spline's, so no ratio can be read off; "
                "neither confirmed nor refuted." % what)
    low, high, mid = min(measured), max(measured), statistics.median(measured)
    if low >= CONFIRMING_RATIO:
        outcome = "confirmed: the BCC quintic needs at most half the samples (within 10%)"
    elif high >= CONFIRMING_RATIO:
        outcome = "confirmed only in part of the range"
    elif low >= 1.0:
        outcome = ("not confirmed: the BCC quintic is more efficient, by a factor of %s (median), not %s"
                   % (number(mid, 3), number(CLAIMED_RATIO, 2)))
    elif high >= 1.0:
        outcome = "not confirmed: the BCC quintic is more efficient only in part of the range"
    else:
        outcome = "not confirmed: the CC B-spline needs fewer samples throughout"
    return ("%s: CC tricubic B-spline samples / BCC quintic samples for the same error = %s to %s (median %s, "
            "%d of %d CC points in range); \"twice as efficient\" %s."
            % (what, number(low, 3), number(high, 3), number(mid, 3), len(measured), len(ratios), outcome))


def _ns_text(values):
    values = [v for v in values if v is not None]
    return number(statistics.median(values), 3) if values else "n/a"


def _orders_text(series):
    o = orders(series)
    return ", ".join("%.2f" % p for p in o) if o else "-"


# ---- analytic runs ---------------------------------------------------------------------------------

def analytic_curves(c):
    """{(interpolator, derivatives): (lattice type, [(samples, rms, point)])} of a convergence
    block, the points sorted by their lattice's samples."""
    curves = {}
    for curve in c["curves"]:
        pts = sorted(((p["lattice_points"], p["rms"], p) for p in curve["points"]), key=lambda x: x[0])
        curves[split_curve_id(curve["id"])] = (curve["lattice_type"], pts)
    return curves


def analytic_filter_table(c):
    """One row per filter: RMS at every requested sample count (matched across lattices),
    successive orders, the median evaluation time and the preparation time at the largest count."""
    requested = sorted({p["samples_requested"] for curve in c["curves"] for p in curve["points"]})
    table = Table(["filter", "lattice"] + ["RMS at %s" % count(n) for n in requested] +
                  ["orders (successive)", "eval (ns/point)", "prepare (s), largest"])
    for (interpolator, derivatives), (kind, pts) in analytic_curves(c).items():
        by_request = {p["samples_requested"]: p for _, _, p in pts}
        cells = [number(by_request[n]["rms"]) if n in by_request else "-" for n in requested]
        largest = pts[-1][2] if pts else {}
        table.add([reconstruction_label(interpolator, derivatives), kind] + cells +
                   [_orders_text([(n, e) for n, e, _ in pts]), _ns_text([p.get("eval_ns_per_point") for _, _, p in pts]),
                    number(largest["prepare_seconds"], 3) if "prepare_seconds" in largest else "n/a"])
    return table


def ratio_table(reference, candidates, error_name):
    """CC B-spline samples and error, then per candidate the samples it needs and the ratio."""
    header = ["CC samples", "cc_bspline3 %s" % error_name]
    for key in candidates:
        header += ["%s samples" % key[0], "ratio"]
    table = Table(header)
    columns = [efficiency_ratios(reference, candidates[key]) for key in candidates]
    for i, (n, e) in enumerate(reference):
        row = [count(n), number(e)]
        for col in columns:
            _, _, m, ratio = col[i]
            row += [count(m) if m else "out of range", number(ratio, 3) if ratio else "-"]
        table.add(row)
    return table


def efficiency_of_analytic(c):
    """(reference series, {candidate: series}) of RMS versus samples, or None without the pair."""
    curves = analytic_curves(c)
    if REFERENCE not in curves or CANDIDATES[0] not in curves:
        return None
    series = {key: [(n, e) for n, e, _ in curves[key][1]] for key in (REFERENCE,) + CANDIDATES if key in curves}
    return series[REFERENCE], {k: v for k, v in series.items() if k != REFERENCE}


# ---- reconstruction sweeps ---------------------------------------------------------------------------

def sweep_series(run, error):
    """{(interpolator, derivatives): (lattice type, [(lattice points, error, rec)])} over a
    sweep's points; error: "band" or "domain" RMS in mesh units."""
    series = {}
    for point in run.points:
        points_of = {l["label"]: (l["lattice"]["type"], l["lattice"]["points"]) for l in point.metrics["lattices"]}
        for rec in point.metrics["reconstructions"]:
            kind, n = points_of[rec["lattice"]]
            series.setdefault((rec["interpolator"], rec["derivatives"]), (kind, []))[1].append(
                (n, rec["errors"][error]["rms"], rec))
    for _, pts in series.values():
        pts.sort(key=lambda x: x[0])
    return series


def sweep_filter_table(run):
    """One row per filter: band RMS (mesh units) at every sweep point, orders, cost."""
    labels = [p.name for p in run.points]
    band = sweep_series(run, "band")
    domain = sweep_series(run, "domain")
    table = Table(["filter", "lattice"] + ["band RMS, %s" % l for l in labels] +
                  ["band orders", "domain orders", "eval (ns/point)", "prepare (s), largest"])
    for key, (kind, pts) in band.items():
        cells = [number(e) for _, e, _ in pts] + ["-"] * (len(labels) - len(pts))
        largest = pts[-1][2] if pts else {}
        table.add([reconstruction_label(*key), kind] + cells +
                  [_orders_text([(n, e) for n, e, _ in pts]), _orders_text([(n, e) for n, e, _ in domain[key][1]]),
                   _ns_text([rec.get("eval_ns_per_point") for _, _, rec in pts]),
                   number(largest["prepare_seconds"], 3) if "prepare_seconds" in largest else "n/a"])
    return table


def efficiency_of_sweep(run, error):
    series = sweep_series(run, error)
    if REFERENCE not in series or CANDIDATES[0] not in series:
        return None
    return ([(n, e) for n, e, _ in series[REFERENCE][1]],
            {k: [(n, e) for n, e, _ in series[k][1]] for k in CANDIDATES if k in series})


# ---- BCC against CC, filter by filter ------------------------------------------------------------------

# Analogous filters of the two lattices: the same data per sample, comparable degree. The
# ratios of the other pairs say whether an advantage belongs to the box spline or to the lattice.
ANALOGUES = ((("trilinear", "fd"), ("bcc_linear", "fd")),
             (("catmull_rom", "fd"), ("bcc_cubic", "fd")),
             (("tricubic_lm", "true"), ("bcc_cubic", "true")),
             (("cc_bspline3", "fd"), ("bcc_box_quintic", "fd")))


def analogue_table(series_sets):
    """series_sets: [(column title, {key: [(samples, error)]})]. One row per analogous pair:
    the median ratio CC samples / BCC samples for the same error, and its range."""
    table = Table(["CC filter", "BCC filter"] + [title for title, _ in series_sets])
    for cc, bcc in ANALOGUES:
        cells = []
        for _, series in series_sets:
            if cc not in series or bcc not in series:
                cells.append("-")
                continue
            ratios = [r for _, _, _, r in efficiency_ratios(series[cc], series[bcc]) if r]
            cells.append("%s (%s-%s)" % (number(statistics.median(ratios), 3), number(min(ratios), 3), number(max(ratios), 3))
                         if ratios else "out of range")
        table.add(["%s/%s" % cc, "%s/%s" % bcc] + cells)
    return table


def analogue_series(runs):
    """[(column title, {key: [(samples, error)]})] of every analytic convergence run and every
    reconstruction sweep (band and domain RMS)."""
    sets = []
    for run in runs:
        if run.kind == "analytic":
            for point in run.points:
                if "convergence" in point.metrics:
                    curves = analytic_curves(point.metrics["convergence"])
                    sets.append(("%s (%s RMS)" % (point.name, point.metrics["convergence"]["function"]),
                                 {k: [(n, e) for n, e, _ in pts] for k, (_, pts) in curves.items()}))
        elif run.kind == "reconstruction" and run.is_sweep:
            for error in ("band", "domain"):
                sets.append(("%s (%s RMS)" % (run.name, error),
                             {k: [(n, e) for n, e, _ in pts] for k, (_, pts) in sweep_series(run, error).items()}))
    return sets


# ---- the section -------------------------------------------------------------------------------------

def claim_summary(runs):
    """[(study, error measure, verdict sentence)] for every study that has the pair; the
    report's summary of the claim and what the tests check."""
    out = []
    for run in runs:
        if run.kind == "analytic":
            for point in run.points:
                c = point.metrics.get("convergence")
                found = efficiency_of_analytic(c) if c else None
                if found:
                    ratios = [r for _, _, _, r in efficiency_ratios(found[0], found[1][CANDIDATES[0]])]
                    what = "%s (%s, RMS)" % (point.name, c["function"])
                    out.append((point.name, "RMS", verdict(ratios, what)))
        elif run.kind == "reconstruction" and run.is_sweep:
            for error in ("band", "domain"):
                found = efficiency_of_sweep(run, error)
                if found:
                    ratios = [r for _, _, _, r in efficiency_ratios(found[0], found[1][CANDIDATES[0]])]
                    out.append((run.name, error, verdict(ratios, "%s (%s RMS)" % (run.name, error))))
    return out


def section(doc, runs):
    doc.heading(2, "Every filter of both lattices, and the \"twice as efficient\" claim")
    doc.paragraph("Each study's filters side by side at matched sample counts: the thesis's (Catmull-Rom, CC tricubic "
                  "of Lekien and Marsden, BCC cubic), bcc_cubic_c0, the BCC box splines (linear; quintic with an "
                  "interpolation prefilter, a quasi-interpolation prefilter, or none) and the prefiltered CC tricubic "
                  "B-spline. Orders are in h between successive sample counts (e ~ h^p, samples ~ h^-3). Evaluation "
                  "time: one thread, double, value and gradient, median over the study's lattices (the harness's "
                  "time_evaluation); prepare: the derivative arrays or the prefilter at the largest lattice, on the "
                  "run's threads. Times are of the machine named in the overview, loaded or not.")
    analytic_points = [(r, p) for r in runs if r.kind == "analytic" for p in r.points if "convergence" in p.metrics]
    sweeps = [r for r in runs if r.kind == "reconstruction" and r.is_sweep]
    if not analytic_points and not sweeps:
        doc.note("No analytic run with \"convergence\" and no reconstruction sweep in the results: run "
                 "`run-experiment configs/ml_efficiency.json` and `configs/dragon_efficiency.json`.")
        return
    for run, point in analytic_points:
        c = point.metrics["convergence"]
        doc.heading(3, "%s: %s, RMS error versus samples" % (point.name, c["function"]))
        padding = {p.get("padding_spacings", 0) for curve in c["curves"] for p in curve["points"]}
        if padding != {0}:
            doc.paragraph("Lattices padded by %s spacings beyond the box (not counted as samples)."
                          % ", ".join(str(p) for p in sorted(padding)))
        doc.table(analytic_filter_table(c))
        found = efficiency_of_analytic(c)
        if found:
            doc.table(ratio_table(found[0], found[1], "RMS"))
    for run in sweeps:
        doc.heading(3, "%s: band RMS (mesh units) versus samples" % run.name)
        doc.table(sweep_filter_table(run))
        for error in ("band", "domain"):
            found = efficiency_of_sweep(run, error)
            if found:
                doc.paragraph("%s RMS: samples the BCC quintic variants need for the CC tricubic B-spline's error "
                              "(log-log interpolation between sweep points)." % error.capitalize())
                doc.table(ratio_table(found[0], found[1], "%s RMS" % error))
    sets = analogue_series(runs)
    if sets:
        doc.heading(3, "BCC against CC, filter by filter")
        doc.paragraph("CC samples / BCC samples for the same error (median, and range over the CC points the BCC curve "
                      "reaches) for analogous filters: whether an advantage belongs to the quintic box spline or to the "
                      "lattice. The tricubic_lm/true and bcc_cubic/true rows read 4 numbers per sample (value and "
                      "gradient); the others 1.")
        doc.table(analogue_table(sets))
    summary = claim_summary(runs)
    doc.heading(3, "The claim, measured")
    if not summary:
        doc.note("No study has both cc_bspline3 and bcc_box_quintic: the claim is not measured here.")
    for _, _, sentence in summary:
        doc.paragraph(sentence)
