import sys, os, glob, numpy as np
dt = np.dtype([("b", "<i8"), ("sm", "<i4"), ("nodes", "<i4"), ("tris", "<i4"), ("box", "<f4"), ("maxd", "<f4"), ("pad", "<i4"), ("t0", "<u8"), ("t1", "<u8")])
for path in sys.argv[1:]:
    a = np.fromfile(path, dtype=dt)
    a = a[a["t1"] > 0]
    t0 = a["t0"].min(); a_s = (a["t0"] - t0) / 1e3; a_e = (a["t1"] - t0) / 1e3; d = a_e - a_s
    end = a_e.max()
    sm_end = np.array([a_e[a["sm"] == s].max() for s in np.unique(a["sm"])])
    print("== %s: %d batches, %d SMs, kernel %.0f us; last batch start %.0f us; SM ends min/med/max %.0f/%.0f/%.0f us; mean SM end %.0f" % (os.path.basename(path), len(a), len(sm_end), end, a_s.max(), sm_end.min(), np.median(sm_end), sm_end.max(), sm_end.mean()))
    q = np.percentile(d, [50, 90, 99, 99.9, 100])
    print("   batch us p50 %.1f p90 %.1f p99 %.1f p99.9 %.1f max %.1f; mean %.1f; nodes mean %.0f p99 %.0f max %d; tris mean %.0f p99 %.0f max %d" % (*q, d.mean(), a["nodes"].mean(), np.percentile(a["nodes"], 99), a["nodes"].max(), a["tris"].mean(), np.percentile(a["tris"], 99), a["tris"].max()))
    print("   corr(d, nodes) %.2f corr(d, tris) %.2f corr(d, box) %.2f corr(d, maxd) %.2f; box p50 %.4f p99 %.4f; maxd p50 %.4f p99 %.4f" % (np.corrcoef(d, a["nodes"])[0,1], np.corrcoef(d, a["tris"])[0,1], np.corrcoef(d, a["box"])[0,1], np.corrcoef(d, a["maxd"])[0,1], np.median(a["box"]), np.percentile(a["box"], 99), np.median(a["maxd"]), np.percentile(a["maxd"], 99)))
    # batches that end after the queue emptied
    late = a_e > a_s.max()
    print("   busy after last start: %d batches; work share of top 1%% batches %.1f%%" % (late.sum(), 100 * np.sort(d)[-len(d)//100:].sum() / d.sum()))
    # timeline: batches in flight per 5% of the kernel
    bins = np.linspace(0, end, 21); inflight = [((a_s < hi) & (a_e > lo)).sum() for lo, hi in zip(bins[:-1], bins[1:])]
    print("   in flight per 5%%: %s" % inflight)
    # cost along the Morton order: duration by batch decile
    order = np.argsort(a["b"]); dd = d[order]; dec = np.array_split(dd, 10)
    print("   mean us by Morton decile: %s" % [round(float(x.mean()), 1) for x in dec])
    top = np.argsort(d)[-8:][::-1]
    for i in top: print("   top b %6d sm %3d start %6.0f dur %6.1f nodes %5d tris %5d box %.4f maxd %.4f" % (a["b"][i], a["sm"][i], a_s[i], d[i], a["nodes"][i], a["tris"][i], a["box"][i], a["maxd"][i]))
