"""Small, schema-valid runs of every kind for the report's tests, written as run
directories (manifest.json, metrics.json, a grid image) into a temporary results tree.
The numbers are chosen so that the tests can find them in the report."""

import copy
import json
import os

import numpy as np
import matplotlib.image as mpimg


def manifest(name, kind, finished="2026-02-01T00:00:00Z", run_id=None, gpu=None, check=None):
    m = {"run_id": run_id or finished.replace(":", "") + "-00000000",
         "name": name, "kind": kind, "description": "Fake %s run." % name,
         "config": {"path": "/x/configs/%s.json" % name, "files": ["/x/configs/%s.json" % name], "sha256": "ab" * 32,
                    "as_written": {}, "resolved": {}},
         "started": finished, "finished": finished,
         "cache": {"used": True, "root": "/x/cache"},
         "provenance": {"host": "test", "cpu": {"model": "Test CPU", "hardware_threads": 2},
                        "gpu": gpu, "build": {"build_type": "Release"},
                        "git": {"commit": "0123456789abcdef", "dirty": False},
                        "load_average": {"start": [0.5, 0.4, 0.3], "end": [0.75, 0.5, 0.3]}},
         "inputs": {}}
    if check is not None:
        m["check"] = check
    return m


def mesh(name="dragon", source="/x/dragon.obj", triangles=99902, vertices=49953):
    return {"name": name, "source": source, "sha256": "cd" * 32, "vertices": vertices, "triangles": triangles,
            "bounds": {"min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 1.0]},
            "report": {"input_vertices": vertices, "input_triangles": triangles, "welded_vertices": 0,
                       "degenerate_triangles": 0, "boundary_edges": 0, "nonmanifold_edges": 0, "inconsistent_edges": 0,
                       "components": 1, "signed_volume": 0.5, "flipped": False, "sign_reliable": True}}


def lattice(kind, n):
    z = 2 * n if kind == "bcc" else n
    points = n ** 3 + (n - 1) ** 3 if kind == "bcc" else n ** 3
    return {"type": kind, "origin": [0.0, 0.0, 0.0], "spacing": 1.0 / n, "resolution": [n, n, z],
            "notation": "%dx%dx%d" % (n, n, z), "points": points}


def field_sampler(threads=2):
    return {"backend": "cpu", "method": "brute_force", "kernel": "vectorized", "precision": "float",
            "points_computed": 512, "threads": threads}


def obtained(kind, n, seconds=2.5, from_cache=False):
    return {"lattice": lattice(kind, n), "cache_key": "ef" * 32, "from_cache": from_cache, "sampler": field_sampler(),
            "seconds": seconds, "kernel_seconds": seconds * 0.8, "pairs_per_second": 1.25e9}


def reconstruction_entry(label, interpolator, derivatives, panel, scale=1.0):
    return {"id": "%s/%s/%s" % (label, interpolator, derivatives), "lattice": label, "interpolator": interpolator,
            "derivatives": derivatives, "description": "%s/%s" % (interpolator, derivatives), "thesis_panel": panel,
            "errors": {"domain": {"count": 100, "rms": 0.01 * scale, "mean_abs": 0.005 * scale, "max_abs": 0.1 * scale},
                       "band": {"count": 80, "rms": 0.02 * scale, "mean_abs": 0.01 * scale, "max_abs": 0.1 * scale,
                                "gradient_angle_mean_deg": 3.5, "gradient_angle_p95_deg": 9.25},
                       "max_abs": 0.1 * scale}}


def image_metrics(mean):
    summary = {"mean": mean, "p95": 2 * mean, "max": 4 * mean}
    return {"pixels": 100, "hit_test": 50, "hit_reference": 50, "hit_both": 49, "only_test": 1, "only_reference": 1,
            "coverage_mismatch": 2, "coverage_mismatch_fraction": 0.02, "normal_angle_degrees": summary,
            "depth_world": summary, "shade_rmse": 0.05, "length_unit": 0.1, "depth_in_length_units": summary}


PANELS = [("A", "catmull_rom/fd", "Catmull-Rom (8x8x8)"), ("B", "bcc_cubic/true", "BCC cubic, true derivatives (6x6x12)"),
          ("C", "bcc_cubic/fd", "BCC cubic, estimated derivatives (6x6x12)"),
          ("D", "tricubic_lm/true", "CC tricubic, true derivatives (8x8x8)"),
          ("E", "tricubic_lm/fd", "CC tricubic, estimated derivatives (8x8x8)")]


def render_view(grid_file):
    return {"camera": {"name": "front"}, "reference": {"renderer": "mesh_reference"},
            "panels": [{"letter": letter, "label": "%s  %s" % (letter, label),
                        "render": {"reconstruction": rec, "seconds": 0.125}, "metrics": image_metrics(4.0 + i)}
                       for i, (letter, rec, label) in enumerate(PANELS)],
            "grid": {"size": [60, 40], "downsample": 1, "heat_max_degrees": 20.0, "labels": "row 1 ..."},
            "grid_file": grid_file}


def reconstruction_metrics(scale=1.0, n=8, render=False, figures=("5-3",)):
    cc, bcc = "cc-%dx%dx%d" % (n, n, n), "bcc-%dx%dx%d" % (n - 2, n - 2, 2 * (n - 2))
    m = {"mesh": mesh(),
         "lattices": [dict(obtained("cc", n), label=cc), dict(obtained("bcc", n - 2, from_cache=True), label=bcc)],
         "probes": {"domain": 100, "band_placed": 100, "in_band": 80, "band_width": 0.5, "band_spacings": 1.0,
                    "h_ref": 0.5, "seed": 1, "box": [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]},
         "reconstructions": [reconstruction_entry(cc, "trilinear", "fd", "", scale),
                             reconstruction_entry(cc, "catmull_rom", "fd", "A", scale),
                             reconstruction_entry(cc, "tricubic_lm", "fd", "E", scale),
                             reconstruction_entry(bcc, "bcc_cubic", "true", "B", scale)],
         "thesis_figures": list(figures),
         "regression": {"probes/in_band": {"value": 80, "kind": "exact"}}}
    if render:
        m["render"] = {"views": {"front": render_view("images/front/dragon_front_grid.png")}}
    return m


def sweep_metrics(points):
    return {"points": [{"name": name, "parameters": {"lattices": []}, "metrics": {k: v for k, v in m.items() if k != "regression"}}
                       for name, m in points],
            "sweep": ["lattices"], "regression": {}}


def sampling_metrics():
    fields = []
    for kind, n in (("cc", 8), ("bcc", 6)):
        f = obtained(kind, n, seconds=0.75)
        f.update({"name": "box-%s-%d" % (kind, n), "upload_seconds": 0.0, "download_seconds": 0.0, "pairs": 6144.0,
                  "distance_min": -0.5, "distance_max": 0.75, "points_inside": 27})
        fields.append(f)
    return {"mesh": mesh("box", "procedural box", 12, 8), "fields": fields,
            "regression": {"box-cc-8/points": {"value": 512, "kind": "exact"}}}


def sampler_options(name_threads):
    return {"backend": "cpu" if name_threads is not None else "cuda", "method": "brute_force", "kernel": "",
            "threads": name_threads or 0, "precision": "float", "bcc_strategy": "two_grids", "device": 0,
            "max_points_per_piece": 0, "max_triangles_per_chunk": 0, "points_per_thread": 0}


def speedup_backend(name, threads, total, extrapolated=False, reference_total=None):
    b = {"name": name, "sampler": sampler_options(threads), "status": "ok", "total_seconds_median": total,
         "seconds_median": total, "seconds_min": total, "seconds_max": total, "seconds_all": [total],
         "points_timed": 1024, "extrapolated": extrapolated, "pairs_per_second": 3.5e9 / total}
    if reference_total is not None:
        b["speedup_vs_reference"] = reference_total / total
    return b


def speedup_metrics():
    dragon = mesh("dragon", "/x/dragon-legacy.obj", 100000, 50000)
    dragon["thesis_table_3_1"] = {"triangles": 100000, "vertices": 50000}
    rows = []
    for samples, n, total in ((32768, 32, 40.0), (262144, 64, 320.0)):
        row = {"mesh": "dragon", "samples_requested": samples, "lattice": "cc", "resolution": "%dx%dx%d" % (n, n, n),
               "points": n ** 3, "triangles": 100000,
               "backends": [speedup_backend("cpu_1", 1, total, True, total),
                            speedup_backend("cpu_all", 0, total / 8, True, total),
                            {"name": "gpu_tuned", "sampler": sampler_options(None),
                             "status": "unavailable (no CUDA device or no CUDA backend in this build)"}]}
        if samples == 32768:
            row["thesis"] = {"gpu_seconds": 1.2325, "cpu_seconds": 383.6, "speedup": 311.0, "gpu": "GeForce GTX 465"}
        rows.append(row)
    return {"meshes": {"dragon": dragon}, "rows": rows, "reference": "cpu_1",
            "regression": {"dragon/32768/cc/cpu_all/speedup": {"value": 8.0, "kind": "speedup"}}}


def analytic_result(rms, lattice_text="111x111x222", points=2745473):
    return {"description": "bcc_cubic/fd", "lattice": lattice_text, "lattice_points": points, "probes": 4096,
            "probe_box": [[-0.9, -0.9, -0.9], [0.9, 0.9, 0.9]], "rms": rms, "max_abs": 10 * rms, "mean_abs": rms / 2,
            "l2_norm": rms * 64, "rms_255": rms * 255, "l2_norm_255": rms * 255 * 64, "gradient_rms": rms * 30}


def analytic_metrics():
    curves = []
    for curve_id, kind in (("catmull_rom/fd", "cc"), ("tricubic_lm/fd", "cc"), ("bcc_cubic/true", "bcc")):
        points = [dict(analytic_result(r, "%dx%dx%d" % (n, n, n), n ** 3), samples_requested=n ** 3)
                  for r, n in ((1e-5, 16), (1e-6, 32))]
        curves.append({"id": curve_id, "lattice_type": kind, "points": points})
    return {"table_4_1": {"function": "marschner_lobb", "lattice": "111x111x222", "margin_spacings": 2.0, "sigma2": 0.5,
                          "sigma_units": "lattice_units", "plain": analytic_result(0.035), "weighted": analytic_result(0.0343),
                          "ratio_rms": 0.98,
                          "thesis": {"dataset": "ML", "plain": 8.939, "weighted": 8.725, "ratio": 8.725 / 8.939}},
            "convergence": {"function": "trig", "curves": curves},
            "regression": {"table_4_1/ratio_rms": {"value": 0.98, "kind": "error"}}}


def peers_metrics():
    base = {"mesh": "bunny", "resolution": "64x64x64", "points": 262144, "triangles": 69664}
    bvh = dict(base, method="bvh_cpu", by="ours", build_seconds=0.05, query_seconds=0.5, total_seconds=0.55,
               points_per_second=524288.0, cpu_seconds=1.0, threads=2, max_abs_error=0.0, max_abs_error_unsigned=0.0,
               mean_abs_error=0.0, compared_points=262144, sign_disagreements=0, notes="reference field")
    peer = dict(base, method="embree", by="peer", version="4.0", exact=True, build_seconds=0.1, query_seconds=2.5,
                total_seconds=2.6, points_per_second=104857.6, cpu_seconds=5.0, threads=2, max_abs_error=1e-7,
                max_abs_error_unsigned=1e-7, mean_abs_error=1e-8, compared_points=262144,
                sign_disagreements="n/a (unsigned)", details={})
    vdb = dict(peer, method="openvdb", version="10.0", exact=False, sign_disagreements=3,
               band={"points_in_band": 1000, "max_abs_error_in_band": 1e-3, "mean_abs_error_in_band": 1e-4,
                     "sign_disagreements_in_band": 0, "max_abs_error_outside_band": 0.25,
                     "sign_disagreements_outside_band": 3})
    gpu = dict(base, method="bvh_gpu", by="ours", status="unavailable (no CUDA device or no CUDA backend in this build)")
    return {"peers": {"embree": {"version": "4.0", "exact": True}, "cgal": {"status": "not built"}},
            "machine": {"hardware_threads": 2}, "meshes": {"bunny": mesh("bunny", "/x/bunny.obj", 69664, 34834)},
            "rows": [bvh, gpu, peer, vdb],
            "summary": [{"mesh": "bunny", "resolution": "64x64x64", "threads": 2, "fastest_exact_peer": "embree",
                         "query_speedup": 5.0, "total_speedup": 4.75, "cpu_time_ratio": 5.0, "goal": 1.5}],
            "regression": {"bunny/64x64x64/2/bvh_cpu_vs_fastest_peer": {"value": 5.0, "kind": "speedup"}}}


def peers_point_set_metrics():
    """A point-set run with the check recorded: Open3D fails on signs, FCPW passes unsigned."""
    base = {"mesh": "dragon", "resolution": "uniform_box/1000", "points": 1000, "triangles": 100000,
            "point_set": {"kind": "uniform_box", "count": 1000, "sigma": None, "seed": 1}}
    timing = dict(build_seconds=0.1, query_seconds=0.2, total_seconds=0.3, points_per_second=5000.0, cpu_seconds=0.3,
                  threads=2, max_abs_error=0.0, max_abs_error_unsigned=0.0, mean_abs_error=0.0, compared_points=1000,
                  check_tolerance=1e-4)
    bvh = dict(base, method="bvh_cpu", by="ours", sign_disagreements=0, sign_disagreements_beyond_tolerance=0,
               passes_check=True, check="exact, signed", signed=True, notes="reference", **timing)
    fcpw = dict(base, method="fcpw", by="peer", version="snapshot abc", exact=True, sign_disagreements="n/a (unsigned)",
                passes_check=True, check="exact, unsigned (no sign returned)", signed=False, details={},
                **dict(timing, query_seconds=0.6, total_seconds=0.7))
    open3d = dict(base, method="open3d", by="peer", version="0.16.1", exact=True, sign_disagreements=400,
                  sign_disagreements_beyond_tolerance=400, passes_check=False,
                  check="max |distance error| 0.5 > tolerance 0.0001", signed=True, details={},
                  **dict(timing, query_seconds=0.1, total_seconds=0.2, max_abs_error=0.5))
    cubql = dict(base, method="cubql", by="peer", status="not built: this build has no CUDA backend")
    return {"peers": {"fcpw": {"version": "snapshot abc", "exact": True, "gpu": False}, "cubql": {"status": "not built"}},
            "machine": {"hardware_threads": 2}, "meshes": {"dragon": mesh("dragon", "/x/dragon.obj", 100000, 50000)},
            "check": {"tolerance_relative_to_diagonal": 1e-5, "rule": "see docs/bvh-peers.md", "our_sign": "auto"},
            "rows": [bvh, fcpw, open3d, cubql],
            "summary": [{"mesh": "dragon", "resolution": "uniform_box/1000", "threads": 2, "ours": "bvh_cpu",
                         "fastest_exact_peer": "fcpw", "fastest_exact_peer_signed": False, "query_speedup": 3.0,
                         "total_speedup": 2.33, "cpu_time_ratio": 2.33, "goal": 3.0, "ours_passes_check": True},
                        {"mesh": "dragon", "resolution": "uniform_box/1000", "threads": 1, "ours": "bvh_cpu",
                         "fastest_exact_peer": "fcpw", "fastest_exact_peer_signed": False, "query_speedup": 3.0,
                         "total_speedup": 2.33, "cpu_time_ratio": 2.33, "goal": 3.0, "ours_passes_check": False,
                         "ours_check": "3 wrong signs farther than the tolerance from the surface"}],
            "regression": {"dragon/uniform_box/1000/2/bvh_cpu_vs_fastest_peer": {"value": 3.0, "kind": "speedup"}}}


def peers_honest_metrics():
    """A point-set run whose rows record their sign and whose summary compares only rows that
    pass their checks: our pseudonormal row fails (18 wrong signs), the exact-sign row is the
    basis at 16 threads, and at 1 thread nothing of ours passes."""
    base = {"mesh": "dragon", "resolution": "gaussian_surface(0.01)/1000", "points": 1000, "triangles": 100000,
            "point_set": {"kind": "gaussian_surface", "count": 1000, "sigma": 0.01, "seed": 2}}
    wrong = "18 wrong signs farther than the tolerance"

    def timed(method, by, threads, query, sign, passes, check, **extra):
        row = dict(base, method=method, by=by, threads=threads, build_seconds=0.1, query_seconds=query,
                   total_seconds=0.1 + query, points_per_second=1000 / query, cpu_seconds=query, max_abs_error=0.0,
                   max_abs_error_unsigned=0.0, mean_abs_error=0.0, compared_points=1000, check_tolerance=1e-4,
                   sign=sign, signed=sign != "none", passes_check=passes, check=check, exact=True,
                   sign_disagreements="n/a (unsigned)" if sign == "none" else (0 if passes else 18), **extra)
        if sign != "none":
            row["sign_disagreements_beyond_tolerance"] = 0 if passes else 18
        return row

    rows = [timed("bvh_cpu_exact_sign", "ours", 16, 3.53, "winding", True, "exact, signed", notes="the reference"),
            timed("bvh_cpu", "ours", 16, 1.0, "pseudonormal", False, wrong, notes="sign pseudonormal"),
            timed("fcpw", "peer", 16, 3.03, "none", True, "exact, unsigned (no sign returned)", version="snapshot abc",
                  details={}),
            timed("cgal", "peer", 16, 20.0, "own", False, "5 wrong signs", version="5.5.1", details={},
                  sign_method="Side_of_triangle_mesh (ray casting)"),
            timed("bvh_cpu", "ours", 1, 8.0, "pseudonormal", False, wrong, notes="sign pseudonormal"),
            timed("fcpw", "peer", 1, 40.0, "none", True, "exact, unsigned (no sign returned)", version="snapshot abc",
                  details={})]
    excluded = [{"method": "bvh_cpu", "sign": "pseudonormal", "check": wrong}]
    summary = [{"mesh": "dragon", "resolution": base["resolution"], "threads": 16, "goal": 3.0, "excluded": excluded,
                "ours": "bvh_cpu_exact_sign", "ours_sign": "winding", "ours_passes_check": True,
                "fastest_exact_peer": "fcpw", "fastest_exact_peer_signed": False, "fastest_exact_peer_sign": "unsigned",
                "compared_time": "query_seconds", "query_speedup": 3.03 / 3.53, "total_speedup": 3.13 / 3.63,
                "cpu_time_ratio": 3.03 / 3.53},
               {"mesh": "dragon", "resolution": base["resolution"], "threads": 1, "goal": 3.0, "excluded": excluded,
                "not_compared": "no row of ours passes its check"}]
    return {"peers": {"fcpw": {"version": "snapshot abc", "exact": True, "gpu": False, "sign": "none", "sign_method": ""},
                      "cgal": {"version": "5.5.1", "exact": True, "gpu": False, "sign": "own",
                               "sign_method": "Side_of_triangle_mesh (ray casting)"}},
            "machine": {"hardware_threads": 16}, "meshes": {"dragon": mesh("dragon", "/x/dragon.obj", 100000, 50000)},
            "check": {"tolerance_relative_to_diagonal": 1e-5, "rule": "see docs/bvh-peers.md", "our_sign": "auto",
                      "our_sign_point_sets": "pseudonormal"},
            "rows": rows, "summary": summary,
            "regression": {"dragon/gaussian_surface(0.01)/1000/16/bvh_cpu_exact_sign_vs_fastest_peer":
                           {"value": 3.03 / 3.53, "kind": "speedup"}}}


def write_run(results, name, kind, metrics, run_id="r1", **manifest_args):
    """results/<name>/<run_id>/ with manifest.json and metrics.json; returns its path."""
    path = os.path.join(str(results), name, run_id)
    os.makedirs(path, exist_ok=True)
    with open(os.path.join(path, "manifest.json"), "w") as f:
        json.dump(manifest(name, kind, **manifest_args), f)
    with open(os.path.join(path, "metrics.json"), "w") as f:
        json.dump(metrics, f)
    return path


def write_grid(path, width=60, height=40):
    """A small grid image: a grey ramp and a viridis band."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    pixels = np.ones((height, width, 3))
    pixels[: height // 2] = np.linspace(0.2, 0.9, width)[None, :, None]
    pixels[height // 2:, :, 0] = 0.27
    pixels[height // 2:, :, 1] = np.linspace(0.0, 0.9, width)[None, :]
    pixels[height // 2:, :, 2] = 0.5
    mpimg.imsave(path, pixels)


def full_tree(results):
    """A results tree with a run of every kind (two of dragon: only the later is reported) and
    a sweep with a rendered grid per point."""
    write_run(results, "dragon", "reconstruction", reconstruction_metrics(scale=100.0), run_id="r1",
              finished="2026-01-01T00:00:00Z")
    dragon = write_run(results, "dragon", "reconstruction", reconstruction_metrics(render=True), run_id="r2",
                       check={"baseline": "results/baselines/dragon.json", "passed": True, "ok": 41, "failed": 0,
                              "not_comparable": 0, "missing": 0, "added": 0})
    write_grid(os.path.join(dragon, "images/front/dragon_front_grid.png"))
    sweep = write_run(results, "pawn_sweep", "reconstruction",
                      sweep_metrics([("pawn_sweep-33k", reconstruction_metrics(2.0, 8, render=True)),
                                     ("pawn_sweep-200k", reconstruction_metrics(1.0, 12, render=True))]))
    for point in ("pawn_sweep-33k", "pawn_sweep-200k"):
        write_grid(os.path.join(sweep, point, "images/front/dragon_front_grid.png"))
    write_run(results, "ml", "analytic", analytic_metrics())
    write_run(results, "speedup", "speedup", speedup_metrics())
    write_run(results, "peers", "peers", peers_metrics())
    write_run(results, "dragon_32k", "sampling", sampling_metrics())


def deep_copy(value):
    return copy.deepcopy(value)
