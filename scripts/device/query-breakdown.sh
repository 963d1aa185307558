#!/usr/bin/env bash
# Where a GPU point query's time goes (issue 37's near-surface rows), and what the certified
# winding sign costs the lattice kernel, on a lent machine (device tool):
#  1. a query of 1M (QUERY_POINTS) points near dragon-legacy's surface (vertices plus a Gaussian
#     of 0.01 of the diagonal, as the peers' set): the Python module's timings, then every
#     kernel's duration under Nsight Compute (--clock-control none; one pass, no replay);
#  2. sdf-sample --backend cuda at 128^3 and 256^3, twice each, certified and with
#     SDF_WINDING_UNCERTIFIED=1 (the fast value's side: the uncertified kernel), kernel seconds.
#   carry: .gpu-prefix data        run: scripts/device/query-breakdown.sh [build]
# Output under $OUT: summary.txt, ncu-kernels.csv and the logs.
. "$(dirname "$0")/start.sh"
MESH=${MESH:-$PWD/data/meshes/dragon-legacy.obj}
QUERY_POINTS=${QUERY_POINTS:-1048576}
if [ "${1:-}" = build ] || [ ! -x $B/bin/sdf-sample ]; then
    OUT=$OUT scripts/device/gpu-check.sh build || exit 1
fi
export SDF_DATA_PATH=$PWD/data/meshes
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | tee -a "$OUT/summary.txt"

cat > "$OUT/query.py" <<'PY'
import sys, time
import numpy as np
import sdf_lattices as sl
path, n, reps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
mesh = sl.load_mesh(path)
v = np.asarray(mesh.vertices)
diag = float(np.linalg.norm(v.max(0) - v.min(0)))
rng = np.random.default_rng(37)
near = v[rng.integers(0, len(v), n)] + rng.normal(0, 0.01 * diag, (n, 3))
sdf = sl.SDF(mesh, backend="cuda")
sdf.query(near[:1000])
for _ in range(reps):
    t = time.perf_counter()
    r = sdf.query(near)
    wall = time.perf_counter() - t
    ts = r.timings_seconds
    print("query %d points: wall %.2f ms, kernel %.2f ms, upload %.2f ms, download %.2f ms, total %.2f ms" %
          (n, 1e3 * wall, 1e3 * ts["kernel"], 1e3 * ts["upload"], 1e3 * ts["download"], 1e3 * ts["total"]), flush=True)
PY
log "query timings (no profiler)"
PYTHONPATH=$B/python python3 "$OUT/query.py" "$MESH" "$QUERY_POINTS" 5 2>&1 | tee -a "$OUT/summary.txt"
log "query kernels under ncu (the last query's launches)"
NCU=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
PYTHONPATH=$B/python timeout 240 "$NCU" --clock-control none --metrics gpu__time_duration.sum --csv \
    python3 "$OUT/query.py" "$MESH" "$QUERY_POINTS" 2 > "$OUT/ncu-kernels.csv" 2> "$OUT/ncu.log"
echo "ncu exit $?" | tee -a "$OUT/summary.txt"
python3 - "$OUT/ncu-kernels.csv" <<'PY' | tee -a "$OUT/summary.txt"
import csv, sys
rows = [r for r in csv.reader(l for l in open(sys.argv[1]) if l.startswith('"'))]
if not rows: sys.exit("no ncu rows")
h = rows[0]; rows = rows[1:]
ki, vi, ui = h.index("Kernel Name"), h.index("Metric Value"), h.index("Metric Unit")
# The second query's kernels: everything after the last morton_keys but one.
starts = [i for i, r in enumerate(rows) if "morton_keys" in r[ki]]
last = rows[starts[-1]:] if starts else rows
total = 0.0
for r in last:
    us = float(r[vi].replace(",", "")) / (1e3 if r[ui] == "nsecond" else 1.0 if r[ui] == "usecond" else 1e-3)
    total += us
    print("%10.1f us  %s" % (us, r[ki][:110]))
print("%10.1f us  all kernels of the last query" % total)
PY

log "certified vs uncertified winding sign, sdf-sample --backend cuda (kernel seconds)"
for res in 128 256; do
    for mode in certified uncertified; do
        for rep in 1 2; do
            rm -f /tmp/qb.json /tmp/qb.*.raw
            if [ $mode = uncertified ]; then export SDF_WINDING_UNCERTIFIED=1; else unset SDF_WINDING_UNCERTIFIED; fi
            $B/bin/sdf-sample "$MESH" --backend cuda --resolution $res --out /tmp/qb.json --overwrite --quiet > "$OUT/sample-$res-$mode-$rep.log" 2>&1
            python3 -c "
import json; h = json.load(open('/tmp/qb.json')); s = h['sampler']
t = h['timings_seconds']
print('$res^3 $mode: kernel %.2f ms, certified %s, stages %s' % (1e3 * t['kernel'], s['sign']['winding']['certified'], s['winding_sign']))" 2>&1 | tee -a "$OUT/summary.txt"
        done
    done
done
unset SDF_WINDING_UNCERTIFIED
log done
