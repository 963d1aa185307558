import sys, time, hashlib, os
import numpy as np
import sdf_lattices as sl
path, outdir, label = sys.argv[1], sys.argv[2], sys.argv[3]
sets = sys.argv[4].split(",") if len(sys.argv) > 4 else ["near1M", "uni1M", "near16M", "uni16M"]
mesh = sl.load_mesh(path)
sdf = sl.SDF(mesh, backend="cuda")
sdf.query(np.zeros((1000, 3)))
b = sdf.sample("cc", 8).sampler.get("bvh", {})
print("%-10s tree %s" % (label, {k: b.get(k) for k in ("nodes", "leaves", "depth", "largest_leaf", "sah_cost", "max_leaf", "ploc_radius", "device_seconds", "built_on")}), flush=True)
for name in sets:
    if name.startswith("cc"):
        res = int(name[2:]); ks = []
        for _ in range(3):
            f = sdf.sample("cc", res)
            ks.append(f.sampler.get("timings", {}).get("kernel", f.seconds) if isinstance(f.sampler.get("timings"), dict) else f.seconds)
        h = hashlib.sha1(np.ascontiguousarray(f.values).tobytes()).hexdigest()[:12]
        print("%-10s %-8s kernel/seconds min %.2f ms  %s  sampler keys %s" % (label, name, 1e3 * min(ks), h, sorted(f.sampler)[:12]), flush=True)
        continue
    pts = np.load(os.path.join(outdir, name + ".npy"))
    ks, ws = [], []
    for _ in range(5):
        t = time.perf_counter()
        r = sdf.query(pts)
        ws.append(time.perf_counter() - t)
        ks.append(r.timings_seconds["kernel"]); c = r.search_certificate
    h = hashlib.sha1(np.ascontiguousarray(r.distance).tobytes() + np.ascontiguousarray(r.triangle).tobytes()).hexdigest()[:12]
    print("%-10s %-8s kernel min %.3f med %.3f ms  wall min %.2f ms  %s  cert %d rerank %d full %d" % (label, name, 1e3 * min(ks), 1e3 * sorted(ks)[2], 1e3 * min(ws), h, c["points"], c["reranked"], c["full_double"]), flush=True)
