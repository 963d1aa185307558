#!/usr/bin/env python3
"""What a user waits for on the GPU machine between a mesh file and exactly signed distances at
1M near-surface points (issue 37): the mesh's load and preparation with and without the
self-intersection check, the CUDA SDF's construction, and the query, wall time (best of 3
after a warm-up).
    PYTHONPATH=build-gpu/python python3 scripts/device/user-wait-sign.py MESH..."""
import sys

import numpy as np
import sdf_lattices as sl
from timing import best  # scripts/device/timing.py



for path in sys.argv[1:]:
    for check in (False, True):
        print("%s load_mesh(check_intersections=%s): %.1f ms" %
              (path, check, 1e3 * best(lambda: sl.load_mesh(path, check_intersections=check))))
    mesh = sl.load_mesh(path)
    print("  report:", {k: v for k, v in mesh.report.items() if "intersect" in k or k in ("closed", "components")})
    print("  SDF(mesh, backend='cuda'): %.1f ms" % (1e3 * best(lambda: sl.SDF(mesh, backend="cuda"))))
    sdf = sl.SDF(mesh, backend="cuda")
    v = np.asarray(mesh.vertices)
    diag = float(np.linalg.norm(v.max(0) - v.min(0)))
    rng = np.random.default_rng(37)
    near = (v[rng.integers(0, len(v), 1 << 20)] + rng.normal(0, 0.01 * diag, (1 << 20, 3))).astype(np.float32)
    print("  SDF.query(1M near-surface points, NumPy): %.1f ms" % (1e3 * best(lambda: sdf.query(near))))
    print("  sign:", sdf.sign, "|", sdf.sign_reason, "| build_seconds", sdf.build_seconds)
