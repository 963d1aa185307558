#!/usr/bin/env python3
"""Open3D peer for the "peers" experiment (called by open3d_peer.cpp).

Open3D's C++ package (libopen3d-dev 0.16 on Debian 12) works, but linking it into the
project pulls its whole dependency tree into our build; the Python module
(python3-open3d) is what Open3D users call, so the experiment calls it here:

    open3d_peer.py DIR THREADS

DIR holds vertices.f32 (n x 3 float32), triangles.u32 (m x 3 uint32) and points.f32
(p x 3 float32). Writes DIR/signed.f32 (RaycastingScene.compute_signed_distance: the
closest point from Embree's point query, the sign by counting ray intersections) and
prints one JSON line with the version and the timings of the Open3D calls alone (file
input/output excluded). Open3D builds its Embree scene on the first query, so "build" is
add_triangles plus a one-point query.
"""
import json
import sys
import time

import numpy as np
import open3d as o3d


def main():
    folder, threads = sys.argv[1], int(sys.argv[2])
    vertices = np.fromfile(f"{folder}/vertices.f32", dtype=np.float32).reshape(-1, 3)
    triangles = np.fromfile(f"{folder}/triangles.u32", dtype=np.uint32).reshape(-1, 3)
    points = np.fromfile(f"{folder}/points.f32", dtype=np.float32).reshape(-1, 3)
    query = o3d.core.Tensor(points)

    cpu_start = time.process_time()
    start = time.perf_counter()
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(vertices), o3d.core.Tensor(triangles))
    scene.compute_distance(o3d.core.Tensor(points[:1]), nthreads=threads)  # commits the scene
    build = time.perf_counter() - start

    start = time.perf_counter()
    unsigned = scene.compute_distance(query, nthreads=threads)
    unsigned_seconds = time.perf_counter() - start

    start = time.perf_counter()
    signed = scene.compute_signed_distance(query, nthreads=threads)
    signed_seconds = time.perf_counter() - start
    cpu_seconds = time.process_time() - cpu_start  # all threads, build and both queries

    signed.numpy().astype(np.float32).tofile(f"{folder}/signed.f32")
    del unsigned
    print(json.dumps({"version": o3d.__version__, "build_seconds": build, "unsigned_seconds": unsigned_seconds,
                      "signed_seconds": signed_seconds, "cpu_seconds": cpu_seconds,
                      "threads": threads}))


if __name__ == "__main__":
    main()
