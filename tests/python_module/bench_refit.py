"""Times SDF.refit of a deforming mesh against building a fresh SDF of the moved vertices
(issue 39 item 4); never run by CTest (speed is recorded, not asserted; test_refit.py checks
that both give the same bits).

    PYTHONPATH=build/python python3 tests/python_module/bench_refit.py [MESH] [--backend cpu|cuda] [--repeat N]

MESH defaults to dragon.obj on the data search path. Prints Mesh(moved, faces)
(preparation) and SDF(Mesh(moved, faces)) (preparation and binding) for a fresh build, SDF.refit for the
refit, the best of N in wall and in CPU time, and the speed-ups.
"""
import argparse
import time

import numpy as np

import sdf_lattices as sl


def best(fn, repeat):
    """The best wall time and the best CPU time (all threads: the work, steadier than the wall
    clock on a shared machine) of `repeat` calls, and the last result."""
    walls, cpus, out = [], [], None
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - t)
        cpus.append(time.process_time() - c)
    return (min(walls), min(cpus)), out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mesh", nargs="?", default="dragon.obj")
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    mesh = sl.load_mesh(a.mesh)
    v, f = mesh.input_vertices, mesh.input_faces
    moved = v + 0.002 * np.linalg.norm(v.max(0) - v.min(0)) * np.sin(7.0 * v[:, [1, 2, 0]])
    bound = sl.SDF(mesh, backend=a.backend)
    print(f"{mesh.name}: {len(v)} input vertices, {len(f)} input faces, backend {a.backend}, "
          f"sign {bound.sign}, best of {a.repeat}")
    fresh_mesh, _ = best(lambda: sl.Mesh(moved, f), a.repeat)
    fresh_sdf, fresh = best(lambda: sl.SDF(sl.Mesh(moved, f), backend=a.backend), a.repeat)
    refit_sdf, refitted = best(lambda: bound.refit(moved), a.repeat)
    p = np.random.default_rng(1).uniform(v.min(0), v.max(0), (20000, 3))
    same = np.array_equal(fresh.query(p).distance.view(np.uint64), refitted.query(p).distance.view(np.uint64))
    print(f"  fresh: Mesh(moved, faces) {fresh_mesh[0]:.3f} s wall, {fresh_mesh[1]:.3f} s CPU; "
          f"SDF(Mesh(moved, faces)) {fresh_sdf[0]:.3f} s wall, {fresh_sdf[1]:.3f} s CPU")
    print(f"  refit: SDF.refit(moved) {refit_sdf[0]:.3f} s wall, {refit_sdf[1]:.3f} s CPU; speed-up "
          f"{fresh_sdf[0] / refit_sdf[0]:.2f}x wall, {fresh_sdf[1] / refit_sdf[1]:.2f}x CPU "
          f"({'same bits' if same else 'DIFFERENT'} on 20,000 points)")


if __name__ == "__main__":
    main()
