"""The every-filter section (issue 17): tables at matched sample counts with the evaluation
cost, orders, and the sample-count ratio of the "twice as efficient" claim, on fake runs whose
errors follow known power laws (so the ratios and orders are known exactly)."""
import fake_runs
import pytest
from sdf_report import filters, runs
from sdf_report.document import Document

SAMPLES = [16000, 32000, 64000, 128000]


def power_law(n, constant, order=4.0):
    """An error e = constant * h^order with h ~ samples^(-1/3)."""
    return constant * n ** (-order / 3.0)


def analytic_curve(curve_id, kind, constant, order=4.0, ns=50.0):
    points = []
    for n in SAMPLES:
        p = dict(fake_runs.analytic_result(power_law(n, constant, order), "%d points" % n, n), samples_requested=n)
        p.update(eval_ns_per_point=ns, prepare_seconds=0.25, timed_points=4096, padding_spacings=8)
        points.append(p)
    return {"id": curve_id, "lattice_type": kind, "points": points}


def analytic_metrics(bcc_advantage):
    """cc_bspline3 with e = h^4 and bcc_box_quintic needing 1/bcc_advantage of its samples."""
    quintic = bcc_advantage ** (4.0 / 3.0)  # e_bcc(n) = e_cc(n * advantage)
    curves = [analytic_curve("cc_bspline3/fd", "cc", 1.0, ns=80.0),
              analytic_curve("bcc_box_quintic/fd", "bcc", 1.0 / quintic, ns=300.0),
              analytic_curve("bcc_box_quintic_qi/fd", "bcc", 3.0),
              analytic_curve("bcc_box_quintic_approx/fd", "bcc", 1e3, order=2.0),
              analytic_curve("bcc_cubic/true", "bcc", 0.9)]
    return {"convergence": {"function": "marschner_lobb", "curves": curves}, "regression": {}}


def render(tmp_path, run_list):
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    doc = Document(str(out))
    filters.section(doc, run_list)
    return doc.markdown()


def test_orders_and_ratios_of_power_laws():
    cc = [(n, power_law(n, 1.0)) for n in SAMPLES]
    assert filters.orders(cc) == pytest.approx([4.0, 4.0, 4.0])
    bcc = [(n, power_law(n * 2.0, 1.0)) for n in SAMPLES]  # half the samples for the same error
    rows = filters.efficiency_ratios(cc, bcc)
    assert [r[3] for r in rows[1:]] == pytest.approx([2.0, 2.0, 2.0])
    assert rows[0][3] is None  # CC's coarsest error is above every BCC point: out of range
    assert filters.samples_for_error(bcc, power_law(64000, 1.0)) == pytest.approx(32000)


def test_verdicts_name_the_measured_factor():
    assert "confirmed: the BCC quintic needs at most half" in filters.verdict([2.0, 1.95, None], "x")
    text = filters.verdict([1.1, 1.2, 1.15], "ML")
    assert "1.1 to 1.2 (median 1.15" in text and "not confirmed: the BCC quintic is more efficient, by a factor of 1.15" in text
    assert "CC B-spline needs fewer samples throughout" in filters.verdict([0.5, 0.8], "x")
    assert "no ratio can be read off" in filters.verdict([None, None], "x")


def test_analytic_run_gets_one_table_of_every_filter_and_the_claim(tmp_path, schema):
    run = runs.load_run_dir(fake_runs.write_run(tmp_path / "results", "ml_efficiency", "analytic", analytic_metrics(1.15)),
                            schema)
    md = render(tmp_path, [run])
    assert "### ml_efficiency: marschner_lobb, RMS error versus samples" in md
    assert "Lattices padded by 8 spacings" in md
    assert "| filter | lattice | RMS at 16,000 | RMS at 32,000 | RMS at 64,000 | RMS at 128,000 | orders (successive) |" in md
    # e = h^4: orders 4; cost beside the error
    assert "| cc_bspline3/fd | cc | %s | %s | %s | %s | 4.00, 4.00, 4.00 | 80 | 0.25 |" % tuple(
        "%.3e" % power_law(n, 1.0) for n in SAMPLES) in md
    assert "| bcc_box_quintic_approx/fd | bcc |" in md and "| 2.00, 2.00, 2.00 | 50 |" in md
    assert "| 64,000 | %.3e | 55,652 | 1.15 |" % power_law(64000, 1.0) in md
    assert "not confirmed: the BCC quintic is more efficient, by a factor of 1.15" in md


def test_confirmed_when_the_quintic_needs_half(tmp_path, schema):
    run = runs.load_run_dir(fake_runs.write_run(tmp_path / "results", "ml_efficiency", "analytic", analytic_metrics(2.0)),
                            schema)
    summary = filters.claim_summary([run])
    assert len(summary) == 1
    assert "2 to 2 (median 2" in summary[0][2] and "\"twice as efficient\" confirmed" in summary[0][2]


def sweep_point(n_cc, n_bcc, scale_cc, scale_bcc):
    m = fake_runs.reconstruction_metrics(figures=())
    cc_label, bcc_label = m["lattices"][0]["label"], m["lattices"][1]["label"]
    m["lattices"][0]["lattice"]["points"] = n_cc
    m["lattices"][1]["lattice"]["points"] = n_bcc
    m["reconstructions"] = [fake_runs.reconstruction_entry(cc_label, "cc_bspline3", "fd", "", scale_cc),
                            fake_runs.reconstruction_entry(bcc_label, "bcc_box_quintic", "fd", "", scale_bcc)]
    for rec in m["reconstructions"]:
        rec.update(eval_ns_per_point=100.0, prepare_seconds=0.5, timed_points=65536)
    return m


def test_sweep_table_and_ratios_from_band_and_domain_errors(tmp_path, schema):
    # BCC at the same counts has the CC error of 1.5x the samples: ratio 1.5 at every point
    pts = []
    for i, n in enumerate(SAMPLES):
        cc, bcc = power_law(n, 1e4), power_law(1.5 * n, 1e4)
        pts.append(("dragon_efficiency-%d" % i, sweep_point(n, n, cc, bcc)))
    run = runs.load_run_dir(fake_runs.write_run(tmp_path / "results", "dragon_efficiency", "reconstruction",
                                                fake_runs.sweep_metrics(pts)), schema)
    md = render(tmp_path, [run])
    assert "### dragon_efficiency: band RMS (mesh units) versus samples" in md
    assert "| cc_bspline3/fd | cc |" in md and "| 4.00, 4.00, 4.00 | 4.00, 4.00, 4.00 | 100 | 0.5 |" in md
    summary = filters.claim_summary([run])
    assert [s[1] for s in summary] == ["band", "domain"]
    for _, _, sentence in summary:
        assert "1.5 to 1.5 (median 1.5, 3 of 4" in sentence and "not confirmed" in sentence


def test_no_runs_with_the_pair(tmp_path, schema):
    run = runs.load_run_dir(fake_runs.write_run(tmp_path / "results", "ml", "analytic", fake_runs.analytic_metrics()), schema)
    md = render(tmp_path, [run])
    assert "No study has both cc_bspline3 and bcc_box_quintic" in md
    assert "| catmull_rom/fd | cc | 1.000e-05 | 1.000e-06 | 3.32 | n/a | n/a |" in md  # no costs recorded: n/a


def test_analogous_pairs_show_the_lattice_and_the_filter(tmp_path, schema):
    metrics = analytic_metrics(1.15)
    metrics["convergence"]["curves"] += [analytic_curve("trilinear/fd", "cc", 1e3, order=2.0),
                                         analytic_curve("bcc_linear/fd", "bcc", 1e3 * 1.3 ** (-2.0 / 3.0), order=2.0)]
    run = runs.load_run_dir(fake_runs.write_run(tmp_path / "results", "ml_efficiency", "analytic", metrics), schema)
    md = render(tmp_path, [run])
    assert "| CC filter | BCC filter | ml_efficiency (marschner_lobb RMS) |" in md
    assert "| trilinear/fd | bcc_linear/fd | 1.3 (1.3-1.3) |" in md
    assert "| cc_bspline3/fd | bcc_box_quintic/fd | 1.15 (1.15-1.15) |" in md
    assert "| catmull_rom/fd | bcc_cubic/fd | - |" in md  # no such curves in this run
