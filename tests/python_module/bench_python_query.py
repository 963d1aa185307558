"""Times the package's point queries (docs/python.md, "Speed of the one-liner"); never run by
CTest (speed is recorded, not asserted).

    PYTHONPATH=build/python python3 tests/python_module/bench_python_query.py MESH [N]

Prints, for MESH and N uniform points in its box grown by 10%: the one-liner sl.sdf(mesh, P)
(build + query), SDF(mesh) build, SDF.query(P), SDF.query of 1 point (median of 2000), and
Open3D's RaycastingScene (add_triangles + compute_signed_distance, float32) on the same
points when python3-open3d is installed. With --one-point-only it prints only the 1-point
query: through sl.SDF when the package has it, else through sl.query (the module before the
bound object).
"""
import platform
import statistics
import sys
import time

import numpy as np

import sdf_lattices as sl


def best(fn, repeat=3):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return min(times), out


def one_point(mesh, samples=2000):
    p = np.array([[0.01, 0.02, 0.03]])
    if hasattr(sl, "SDF"):
        s = sl.SDF(mesh, backend="cpu")
        call = lambda: s.query(p)  # noqa: E731
    else:
        call = lambda: sl.query(mesh, p, backend="cpu")  # noqa: E731
        samples = 20
    call()
    times = []
    for _ in range(samples):
        t = time.perf_counter()
        call()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    path, n = args[0], int(args[1]) if len(args) > 1 else 100000
    mesh = sl.load_mesh(path, check_intersections=False)
    print(f"machine: {platform.node()}, {platform.processor() or platform.machine()}; mesh {mesh.name}: "
          f"{len(mesh.faces)} triangles")
    print(f"1-point query: {one_point(mesh) * 1e6:.1f} us (median)")
    if "--one-point-only" in sys.argv:
        return
    lo, hi = np.array(mesh.bounds)
    pad = 0.1 * (hi - lo).max()
    P = np.random.default_rng(0).uniform(lo - pad, hi + pad, size=(n, 3))
    t_one, d = best(lambda: sl.sdf(mesh, P, backend="cpu"))
    for sign in ("auto", "pseudonormal"):
        t_build, s = best(lambda: sl.SDF(mesh, backend="cpu", sign=sign))
        t_query, r = best(lambda: s.query(P))
        print(f"sign={sign}: sl.sdf(mesh, P), {n} points: {t_one if sign == 'auto' else float('nan'):.3f} s; SDF build "
              f"{t_build:.3f} s + query {t_query:.3f} s ({n / t_query / 1e6:.2f} M points/s), sign used {r.sign}")
    try:
        import open3d as o3d
    except ImportError:
        print("open3d: not installed")
        return
    V, F = mesh.vertices.astype(np.float32), mesh.faces.astype(np.uint32)

    def o3d_build():
        scene = o3d.t.geometry.RaycastingScene()
        scene.add_triangles(o3d.core.Tensor(V), o3d.core.Tensor(F))
        return scene

    t_obuild, scene = best(o3d_build)
    Q = o3d.core.Tensor(P.astype(np.float32))
    t_oquery, theirs = best(lambda: scene.compute_signed_distance(Q).numpy())
    diff = np.abs(theirs - d)
    print(f"open3d {o3d.__version__} RaycastingScene: build {t_obuild:.3f} s + compute_signed_distance {t_oquery:.3f} s "
          f"({n / t_oquery / 1e6:.2f} M points/s); |open3d - ours| median {np.median(diff):.2e}, "
          f"sign disagrees at {int(np.sum(np.sign(theirs) != np.sign(d)))} points")


if __name__ == "__main__":
    main()
