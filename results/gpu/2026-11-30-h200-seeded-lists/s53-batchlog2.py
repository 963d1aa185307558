import sys, os, numpy as np
dt = np.dtype([("b", "<i8"), ("sm", "<i4"), ("nodes", "<i4"), ("tris", "<i4"), ("box", "<f4"), ("maxd", "<f4"), ("pad", "<i4"), ("t0", "<u8"), ("t1", "<u8")])
for path in sys.argv[1:]:
    if not os.path.exists(path): continue
    a = np.fromfile(path, dtype=dt); a = a[a["t1"] > 0]
    t0 = a["t0"].min(); s = (a["t0"] - t0) / 1e3; e = (a["t1"] - t0) / 1e3; d = e - s
    sm_end = np.array([e[a["sm"] == x].max() for x in np.unique(a["sm"])])
    print("== %s: %d batches, kernel %.0f us; last start %.0f; SM ends min/mean/max %.0f/%.0f/%.0f; batch us p50 %.1f p99 %.1f max %.1f mean %.1f" % (os.path.basename(path), len(a), e.max(), s.max(), sm_end.min(), sm_end.mean(), sm_end.max(), np.median(d), np.percentile(d, 99), d.max(), d.mean()))
    top = np.argsort(d)[-5:][::-1]
    print("   top: " + "; ".join("b %d start %.0f dur %.0f" % (a["b"][i], s[i], d[i]) for i in top))
