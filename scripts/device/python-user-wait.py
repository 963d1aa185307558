#!/usr/bin/env python3
"""The Python rows of issue 23's table on the GPU machine: sample(mesh, "cc", 256,
backend="cuda"), a built SDF's 1-point query, and one query of 16.8M points as NumPy arrays
and as CUDA tensors (PyTorch), wall time per call (best of 3 after a warm-up).
    PYTHONPATH=build-gpu/python python3 scripts/device/python-user-wait.py MESH"""
import sys
import time

import numpy as np
import sdf_lattices as sl
from timing import best  # scripts/device/timing.py



mesh = sl.load_mesh(sys.argv[1])
print("mesh", mesh)
print("sample(mesh, 'cc', 256, backend='cuda'): %.3f s" % best(lambda: sl.sample(mesh, "cc", 256, backend="cuda")))
t = time.perf_counter()
sdf = sl.SDF(mesh, backend="cuda")
print("SDF(mesh, backend='cuda') build: %.3f s" % (time.perf_counter() - t))
p1 = np.array([[0.01, 0.02, 0.03]])
print("SDF.query(1 point): %.1f us" % (1e6 * best(lambda: sdf.query(p1), 20)))
rng = np.random.default_rng(23)
lo, hi = np.asarray(mesh.vertices).min(0), np.asarray(mesh.vertices).max(0)
pts = (lo + (hi - lo) * rng.random((1 << 24, 3))).astype(np.float32)
print("SDF.query(16.8M points, NumPy float32): %.3f s" % best(lambda: sdf.query(pts)))
try:
    import torch
    tp = torch.from_numpy(pts).cuda()

    def on_device():
        sdf.query(tp)
        torch.cuda.synchronize()
    print("SDF.query(16.8M points, torch CUDA float32): %.3f s" % best(on_device))
except Exception as e:  # noqa: BLE001 - a row that cannot run is reported, not fatal
    print("torch row skipped:", e)
try:
    import jax
    print("jax", jax.__version__, jax.devices())
except Exception as e:  # noqa: BLE001
    print("jax not usable:", e)
