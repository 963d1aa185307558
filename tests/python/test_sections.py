"""Each section module on fake runs: the figures they show, taken from the metrics (the
thesis's included), and the notes when a kind has no runs."""
import os

import fake_runs
from sdf_report import analytic, overview, peers, reconstruction, runs, sampling, speedup
from sdf_report.document import Document


def load(tmp_path, schema, name, kind, metrics, **manifest_args):
    return runs.load_run_dir(fake_runs.write_run(tmp_path / "results", name, kind, metrics, **manifest_args), schema)


def render(section, tmp_path, run_list):
    out = tmp_path / "out"
    out.mkdir(exist_ok=True)
    doc = Document(str(out))
    section(doc, run_list)
    return doc.markdown()


def test_overview_shows_machine_load_and_check(tmp_path, schema):
    checked = load(tmp_path, schema, "dragon", "reconstruction", fake_runs.reconstruction_metrics(),
                   check={"baseline": "b.json", "passed": False, "ok": 38, "failed": 2, "not_comparable": 0,
                          "missing": 1, "added": 0})
    plain = load(tmp_path, schema, "ml", "analytic", fake_runs.analytic_metrics(), gpu={"name": "NVIDIA H200"})
    out = tmp_path / "out"
    out.mkdir()
    doc = Document(str(out))
    overview.section(doc, [checked, plain], str(tmp_path))
    md = doc.markdown()
    assert "| dragon | reconstruction | 2026-02-01T000000Z-00000000 | 0123456789 | Test CPU x2 | none | Release | " \
           "0.5/0.75 | FAILED (2 failed, 1 missing) |" in md
    assert "| ml | analytic | 2026-02-01T000000Z-00000000 | 0123456789 | Test CPU x2 | NVIDIA H200 | Release | " \
           "0.5/0.75 | not checked |" in md
    assert "loaded machine" not in md
    busy = fake_runs.manifest("busy", "analytic")
    busy["provenance"]["load_average"]["end"] = [6.5, 5.0, 4.0]
    assert overview.overloaded(runs.Run("x", busy, {}))
    del busy["provenance"]["load_average"]
    assert not overview.overloaded(runs.Run("x", busy, {}))


def test_sampling_times_of_sampling_and_reconstruction_runs(tmp_path, schema):
    s = load(tmp_path, schema, "dragon_32k", "sampling", fake_runs.sampling_metrics())
    r = load(tmp_path, schema, "dragon", "reconstruction", fake_runs.reconstruction_metrics())
    md = render(sampling.section, tmp_path, [s, r])
    assert "| dragon_32k | box-cc-8 | cc 8x8x8 | 512 | 12 | cpu/brute_force/vectorized, 2 threads, float | 0.75 | " \
           "0.6 | 1.25e+09 | 853 | sampled |" in md
    assert "| dragon | bcc-6x6x12 | bcc 6x6x12 | 341 | 99,902 | cpu/brute_force/vectorized, 2 threads, float | 2.5 | " \
           "2 | 1.25e+09 | 170 | cache |" in md
    assert "No sampling or reconstruction run" in render(sampling.section, tmp_path, [])


def test_speedup_tables_take_the_thesis_figures_from_the_metrics(tmp_path, schema):
    metrics = fake_runs.speedup_metrics()
    metrics["rows"][0]["thesis"]["cpu_seconds"] = 999.5  # not the thesis's: shows where the figure comes from
    run = load(tmp_path, schema, "speedup", "speedup", metrics)
    md = render(speedup.section, tmp_path, [run])
    assert "| dragon | dragon-legacy.obj | 100,000 | 50,000 | 100,000 | 50,000 |" in md
    assert "| dragon | 32,768 | cc 32x32x32 | 32,768 | 40* | 5* | n/a | 8 | n/a | 1.232 | 999.5 | 311 |" in md
    assert "| dragon | 262,144 | cc 64x64x64 | 262,144 | 320* | 40* | n/a | 8 | n/a | - | - | - |" in md
    assert "| dragon | cc 32x32x32 | 32,768 | 100,000 | 8.75e+07 | 7e+08 | n/a |" in md  # pairs/s
    assert "![speedup: speedup versus lattice size (CC rows)](speedup_vs_size_speedup.png)" in md
    assert os.path.isfile(tmp_path / "out" / "speedup_vs_size_speedup.png")
    assert "not comparable with the thesis's" not in md
    md = render(speedup.section, tmp_path, [])
    assert "No speedup run in the results" in md


def test_speedup_against_another_reference_is_flagged(tmp_path, schema):
    metrics = fake_runs.speedup_metrics()
    metrics["reference"] = "cpu_all"
    run = load(tmp_path, schema, "gpu_kernels", "speedup", metrics)
    assert "not comparable with the thesis's" in render(speedup.section, tmp_path, [run])
    assert not speedup.reference_is_one_cpu_thread(metrics)  # and the plot leaves the thesis's speedups out
    assert speedup.reference_is_one_cpu_thread(fake_runs.speedup_metrics())


def test_analytic_table_4_1_and_identical_curves(tmp_path, schema):
    metrics = fake_runs.analytic_metrics()
    metrics["table_4_1"]["thesis"]["plain"] = 7.5  # read from the metrics, not from the report's code
    run = load(tmp_path, schema, "ml", "analytic", metrics)
    md = render(analytic.section, tmp_path, [run])
    assert "| plain | 0.035 | 0.35 | 8.925 | 571.2 | 7.5 |" in md
    assert "| weighted / plain | 0.98 |  |  |  | 0.9761 |" in md
    assert "| tricubic_lm/fd (= catmull_rom: same function) | 16x16x16 | 4,096 | 1.000e-05 |" in md
    assert "| catmull_rom/fd | 16x16x16 | 4,096 |" in md
    assert os.path.isfile(tmp_path / "out" / "ml_error_vs_samples.png")


def test_reconstruction_error_tables_sweeps_and_grids(tmp_path, schema):
    single = load(tmp_path, schema, "dragon", "reconstruction", fake_runs.reconstruction_metrics(render=True))
    fake_runs.write_grid(os.path.join(single.path, "images/front/dragon_front_grid.png"))
    sweep = load(tmp_path, schema, "pawn_sweep", "reconstruction", fake_runs.sweep_metrics(
        [("pawn_sweep-33k", fake_runs.reconstruction_metrics(2.0)), ("pawn_sweep-200k", fake_runs.reconstruction_metrics(1.0, 12))]))
    md = render(reconstruction.section, tmp_path, [single, sweep])
    assert "### dragon (thesis Figures 5-3)" in md
    assert "| cc-8x8x8/catmull_rom/fd | A | 0.02 | 0.2 | 0.02 | 0.04 | 3.5 | 9.25 |" in md
    assert "| cc-8x8x8/tricubic_lm/fd (= catmull_rom: same function) | E | 0.02 | 0.2 | 0.02 | 0.04 | 3.5 | 9.25 |" in md
    assert "#### pawn_sweep-200k" in md
    assert "| cc-12x12x12/catmull_rom/fd | A | 0.02 |" in md
    assert "cc-8x8x8 (512 points), bcc-6x6x12 (341 points, from the cache)" in md
    assert "![pawn_sweep: band RMS error versus samples](pawn_sweep_error_vs_samples.png)" in md
    # The grid, its colour scale and its image metrics, E marked as the same function as A.
    assert "![dragon, view front](grid_dragon_front.png)\n\n" \
           "![Colour scale of the heat maps above (0 to 20 degrees)](heat_map_scale_20.png)" in md
    assert "| A | Catmull-Rom (8x8x8) | 4 | 8 | 4 | 2.00% | 0.05 | 0.125 |" in md
    assert "| E | CC tricubic, estimated derivatives (8x8x8) (= A: same function) | 8 | 16 | 8 | 2.00% | 0.05 | 0.125 |" in md
    for png in ("heat_map_scale_20.png", "grid_dragon_front.png", "pawn_sweep_error_vs_samples.png"):
        assert os.path.isfile(tmp_path / "out" / png), png


def test_studies_in_the_order_of_the_thesis_figures(tmp_path, schema):
    def study(name, figures):
        return load(tmp_path, schema, name, "reconstruction", fake_runs.reconstruction_metrics(figures=figures))
    ordered = sorted([study("a_none", ()), study("pawn", ("5-7", "5-11")), study("soccer", ("5-2",)),
                      study("dragon", ("5-3", "5-4"))], key=reconstruction.thesis_order)
    assert [r.name for r in ordered] == ["soccer", "dragon", "pawn", "a_none"]


def test_missing_grid_image_is_a_note(tmp_path, schema):
    run = load(tmp_path, schema, "dragon", "reconstruction", fake_runs.reconstruction_metrics(render=True))
    md = render(reconstruction.section, tmp_path, [run])
    assert "dragon_front_grid.png is missing" in md
    assert "heat_map_scale" not in md
    assert "| B | BCC cubic, true derivatives (6x6x12) | 5 |" in md


def test_peers_rows_status_rows_and_summary(tmp_path, schema):
    run = load(tmp_path, schema, "peers", "peers", fake_runs.peers_metrics())
    md = render(peers.section, tmp_path, [run])
    # a run from before rows recorded their sign: signed or unsigned, from the sign disagreements
    assert "| bunny 64x64x64 | bvh_cpu | ours | 2 | signed | 0.05 | 0.5 | 1 | 5.24e+05 | 0 | 0 | - |  |" in md
    assert "| bunny 64x64x64 | bvh_gpu | ours | - | - | - | - | - | - | - | - | - | unavailable (no CUDA device" in md
    assert ("| bunny 64x64x64 | embree 4.0 | peer | 2 | unsigned | 0.1 | 2.5 | 5 | 1.05e+05 | 1.000e-07 | n/a (unsigned) "
            "| - |  |") in md
    assert "narrow band: max \\|d error\\| 0.001 inside (1,000 points), 0.25 outside" in md
    # A run from before passes_check: the summary says its fastest peer was not checked.
    assert ("| bunny 64x64x64 | 2 | bvh_cpu | embree (exactness not checked: run before passes_check) | 5 | 4.75 | 5 | "
            "1.5 | - |") in md
    assert "No peers run" in render(peers.section, tmp_path, [])


def test_peers_point_sets_check_column_and_unsigned_fastest_peer(tmp_path, schema):
    run = load(tmp_path, schema, "peers", "peers", fake_runs.peers_point_set_metrics())
    md = render(peers.section, tmp_path, [run])
    assert "| yes (unsigned) |" in md
    assert "| no: max \\|distance error\\| 0.5 > tolerance 0.0001 |" in md
    assert "| dragon uniform_box/1000 | 2 | bvh_cpu | fcpw (unsigned: returns no sign) | 3 | 2.33 | 2.33 | 3 | - |" in md
    assert "| 1 | bvh_cpu (fails check: 3 wrong signs farther than the tolerance from the surface) | fcpw" in md
    assert "not built: this build has no CUDA backend" in md


def test_peers_summary_compares_only_rows_that_pass_and_names_every_sign(tmp_path, schema):
    run = load(tmp_path, schema, "peers", "peers", fake_runs.peers_honest_metrics())
    md = render(peers.section, tmp_path, [run])
    # every row says its sign
    assert "| dragon gaussian_surface(0.01)/1000 | bvh_cpu | ours | 16 | pseudonormal | 0.1 | 1 |" in md
    assert "| bvh_cpu_exact_sign | ours | 16 | winding |" in md
    assert "| fcpw snapshot abc | peer | 16 | unsigned |" in md
    assert "| cgal 5.5.1 | peer | 16 | own: Side_of_triangle_mesh (ray casting) |" in md
    # the ratio rests on the exact-sign row, the failing pseudonormal row is listed beside it
    assert ("| dragon gaussian_surface(0.01)/1000 | 16 | bvh_cpu_exact_sign [winding] | fcpw [unsigned] | 0.8584 | 0.8623 "
            "| 0.8584 | 3 | - | bvh_cpu [pseudonormal]: 18 wrong signs farther than the tolerance |") in md
    # no row of ours passes at 1 thread: no ratio
    assert ("| dragon gaussian_surface(0.01)/1000 | 1 | - | not compared: no row of ours passes its check | - | - | - | 3 "
            "| - | bvh_cpu [pseudonormal]: 18 wrong signs farther than the tolerance |") in md


def test_a_grid_that_marks_its_twin_briefly_is_labelled_once_in_full():
    def panel(letter, label, reconstruction):
        return {"letter": letter, "label": letter + "  " + label, "render": {"reconstruction": reconstruction}}
    panels = [panel("A", "Catmull-Rom (8x8x8)", "catmull_rom/fd"),
              panel("E", "CC tricubic, estimated derivatives (= A) (8x8x8)", "tricubic_lm/fd")]
    assert reconstruction.panel_label(panels[1], panels) == "CC tricubic, estimated derivatives (8x8x8) (= A: same function)"
    assert reconstruction.panel_label(panels[0], panels) == "Catmull-Rom (8x8x8)"


def test_a_commit_passed_in_for_a_tree_without_git_is_marked():
    class Stub:
        published = None
        provenance = {"git": {"commit": "0123456789abcdef", "dirty": False, "source": "SDF_SOURCE_COMMIT"}}
    assert overview.commit(Stub()) == "0123456789 (passed in)"
    Stub.provenance = {"git": {"commit": "0123456789abcdef", "dirty": True, "source": "git"}}
    assert overview.commit(Stub()) == "0123456789 (dirty)"
