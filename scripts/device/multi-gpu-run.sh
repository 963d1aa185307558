#!/usr/bin/env bash
# Issue 36's scaling table on a lent machine with several GPUs (nvidia-h200-x2, -x4; device
# tool): a dense CC lattice of the dragon (RES, default 1024^3) and QUERY_POINTS query points
# (default 16,777,216, near the surface) on 1, 2 and 4 GPUs (those visible), one process with
# "devices" and mpirun -np N, each row: the field's kernel, upload and download seconds from
# metrics.json (the slowest device's), and the command's wall clock (mesh, plan, field files on
# disk included). Then the 2-GPU checks: ctest's multi_gpu_test and mpi_gpu.
#   carry: .gpu-prefix data        run: scripts/device/multi-gpu-run.sh [build]
# Builds with scripts/device/gpu-check.sh's "build" step (into build-gpu) when asked or absent.
# Output under $OUT: scaling.md (the table), summary.txt and the logs.
. "$(dirname "$0")/start.sh"
MESH=${MESH:-$PWD/data/meshes/dragon.obj}
RES=${RES:-1024}
QUERY_POINTS=${QUERY_POINTS:-16777216}
FIELDS=${FIELDS:-/tmp/multi-gpu-fields}
if [ "${1:-}" = build ] || [ ! -x $B/bin/run-experiment ]; then
    OUT=$OUT scripts/device/gpu-check.sh build || exit 1
fi
export SDF_DATA_PATH=$PWD/data/meshes
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
gpus=$(nvidia-smi -L | grep -c '^GPU')
nvidia-smi --query-gpu=index,name,pci.bus_id --format=csv,noheader | tee -a "$OUT/summary.txt"
log "$gpus GPUs visible; mesh $MESH; CC ${RES}^3; $QUERY_POINTS query points"

config() {  # name, devices JSON ("" = the default one device)
    local devices=${2:+, \"devices\": $2}
    cat > "$OUT/$1.json" <<JSON
{"name": "$1", "kind": "sampling", "mesh": "$MESH", "domain": {"margin": 0.1},
 "lattices": [{"type": "cc", "resolution": [$RES, $RES, $RES]}],
 "sampler": {"backend": "cuda", "method": "bvh", "progress": false$devices},
 "output": {"dtype": "float32"}}
JSON
}
row() {  # label, command...: runs it, times it, appends the field's timings to rows.txt
    local label=$1; shift
    rm -rf "$FIELDS" && mkdir -p "$FIELDS"
    local t0=$(date +%s.%N)
    "$@" --no-cache --quiet --output-root "$FIELDS" > "$OUT/$label.log" 2>&1
    local rc=$? t1=$(date +%s.%N)
    python3 - "$label" "$rc" "$t0" "$t1" "$FIELDS" >> "$OUT/rows.txt" <<'PY'
import glob, json, sys
label, rc, wall, root = sys.argv[1], int(sys.argv[2]), float(sys.argv[4]) - float(sys.argv[3]), sys.argv[5]
m = glob.glob(f"{root}/*/*/metrics.json")
if rc != 0 or not m:
    print(f"| {label} | failed (exit {rc}) | | | | |"); sys.exit()
f = json.load(open(m[0]))["fields"][0]
s = f["sampler"]
split = s.get("devices", {}).get("split")
ranks = s.get("distributed", {}).get("ranks")
note = f"{ranks} ranks" if ranks else ("split" if split else s.get("devices", {}).get("why_not", "one device"))
k, u, d = f["kernel_seconds"], f["upload_seconds"], f["download_seconds"]
print(f"| {label} | {k:.3f} | {u + d:.3f} | {k + u + d:.3f} | {f['seconds']:.2f} | {wall:.2f} | {note} |")
PY
    tail -1 "$OUT/rows.txt" | tee -a "$OUT/summary.txt"
}

{
echo "# Multi-GPU scaling: CC ${RES}^3 of $(basename "$MESH"), $(nvidia-smi --query-gpu=name --format=csv,noheader | head -1) x $gpus"
echo
echo "| run | kernel s | transfers s | kernel+transfers s | sampling s | wall s (to disk) | how |"
echo "|---|---|---|---|---|---|---|"
} > "$OUT/rows.txt"
# A lent machine's memory grows as it is first used (about 3 s for each 8 GiB: KINDS.md): the
# first run of a 1024^3 field paid for it in its transfers (39 s of the one-GPU row's 40 s on
# 2026-11-29). One untimed run first (WARMUP=0 leaves it out).
if [ "${WARMUP:-1}" = 1 ]; then
    config warmup ""
    log "warm-up run (untimed: the host's memory grows)"
    rm -rf "$FIELDS" && mkdir -p "$FIELDS"
    $B/bin/run-experiment "$OUT/warmup.json" --no-cache --quiet --output-root "$FIELDS" > "$OUT/warmup.log" 2>&1
fi
for n in 1 2 4; do
    [ "$n" -le "$gpus" ] || { log "$n GPUs: not run ($gpus visible)"; continue; }
    list=$(python3 -c "print(list(range($n)))")
    if [ "$n" -eq 1 ]; then config one ""; else config "dev$n" "$list"; fi
    row "1 process, $n GPU(s)" $B/bin/run-experiment "$OUT/$([ "$n" -eq 1 ] && echo one || echo dev$n).json"
    if [ "$n" -gt 1 ]; then
        config "mpi$n" ""
        row "mpirun -np $n" mpirun --bind-to none -np "$n" $B/bin/run-experiment "$OUT/mpi$n.json"
    fi
done
rm -rf "$FIELDS"

log "point queries: $QUERY_POINTS points near the surface, SDF(mesh, devices=...).query"
{
echo
echo "| query | devices | kernel s | upload s | download s | total s |"
echo "|---|---|---|---|---|---|"
} >> "$OUT/rows.txt"
PYTHONPATH=$B/python python3 - "$MESH" "$QUERY_POINTS" "$gpus" >> "$OUT/rows.txt" 2> "$OUT/query.log" <<'PY' || echo "| query | failed: see query.log | | | | |" >> "$OUT/rows.txt"
import sys
import numpy as np
import sdf_lattices as sl
mesh_path, n, gpus = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
mesh = sl.load_mesh(mesh_path)
rng = np.random.default_rng(1)
lo, hi = np.asarray(mesh.vertices).min(0), np.asarray(mesh.vertices).max(0)
v = np.asarray(mesh.vertices)
points = v[rng.integers(0, len(v), n)] + rng.normal(0, 0.01 * np.linalg.norm(hi - lo), (n, 3))
reference = None
for k in (1, 2, 4):
    if k > gpus:
        continue
    sdf = sl.SDF(mesh, backend="cuda", devices=list(range(k)))
    sdf.query(points[:1000])  # warm
    r = sdf.query(points)
    t = r.timings_seconds
    if reference is None:
        reference = r.distance
    same = "same bytes" if np.array_equal(r.distance.view(np.uint64), reference.view(np.uint64)) else "DIFFERENT"
    used = f"{k}" if r.devices["used"] == k else f"{k} ({r.devices['used']} used: below the split threshold)"
    print(f"| {n} points ({same}) | {used} | {t['kernel']:.3f} | {t['upload']:.3f} | {t['download']:.3f} | {t['total']:.3f} |")
PY
cat "$OUT/rows.txt" > "$OUT/scaling.md"
cat "$OUT/scaling.md"

if [ "$gpus" -ge 2 ]; then
    log "2-GPU tests: multi_gpu_test, mpi_gpu"
    (cd $B && ctest -R 'multi_gpu_test|mpi_gpu' --output-on-failure > "$OUT/ctest-multi-gpu.log" 2>&1; echo "ctest exit $?") | tee -a "$OUT/summary.txt"
    grep -E "Test +#|tests passed" "$OUT/ctest-multi-gpu.log" | tee -a "$OUT/summary.txt"
fi
log done
