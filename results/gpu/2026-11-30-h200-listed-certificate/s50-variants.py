import sys, time, hashlib, os
import numpy as np
import sdf_lattices as sl
path, outdir, label = sys.argv[1], sys.argv[2], sys.argv[3]
mesh = sl.load_mesh(path)
sdf = sl.SDF(mesh, backend="cuda")
sdf.query(np.zeros((1000, 3)))
for name in ["near1M", "uni1M", "near16M", "uni16M"]:
    pts = np.load(os.path.join(outdir, name + ".npy"))
    ks, ws = [], []
    for _ in range(5):
        t = time.perf_counter()
        r = sdf.query(pts)
        ws.append(time.perf_counter() - t)
        ks.append(r.timings_seconds["kernel"]); c = r.search_certificate
    h = hashlib.sha1(np.ascontiguousarray(r.distance).tobytes() + np.ascontiguousarray(r.triangle).tobytes()).hexdigest()[:12]
    print("%-10s %-8s kernel min %.3f med %.3f ms  wall min %.2f ms  %s  cert %d rerank %d full %d" % (label, name, 1e3 * min(ks), 1e3 * sorted(ks)[2], 1e3 * min(ws), h, c["points"], c["reranked"], c["full_double"]), flush=True)
