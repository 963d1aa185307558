#!/usr/bin/env bash
# The dragon's sparse narrow band at 4096^3 and 8192^3 (issue 35: "must run on one GPU and on
# the CPU machine"), on a lent machine (device tool): bench_sparse_band with the distance channel
# on the GPU and on the host's CPU cores (the call's wall and CPU time, peak RSS), then sdf-sample
# end to end at 8192^3 (mesh file to the sparse field file in float32 and the .nvdb on the local
# disk) under /usr/bin/time -v, and dd writing as many bytes with fsync (the goal's floor).
#   carry: .gpu-prefix data        run: scripts/device/huge-band.sh [build] [RES...]
# Output under $OUT: summary.txt and the logs.
. "$(dirname "$0")/start.sh"
MESH=${MESH:-$PWD/data/meshes/dragon.obj}
if [ "${1:-}" = build ]; then
    shift
    OUT=$OUT scripts/device/gpu-check.sh build || exit 1
fi
RESOLUTIONS=${*:-4096 8192}
BENCH=${BENCH:-1}  # 0: only the end-to-end runs (FILES: "nvdb", "field+nvdb" or both; BACKENDS: cuda, cpu or both)
DTYPE=${DTYPE:-float32}  # the end-to-end runs' --dtype: float32 holds the band's distances in float32, float64 in double
export SDF_DATA_PATH=$PWD/data/meshes
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee -a "$OUT/summary.txt"
echo "host: $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB" | tee -a "$OUT/summary.txt"
# The numbers a row needs from bench_sparse_band's JSON line and time -v's report.
row() {
    python3 - "$1" "$2" <<'PY' | tee -a "$OUT/summary.txt"
import json, re, sys
j = json.loads([l for l in open(sys.argv[1]) if l.startswith("{")][-1])
t = open(sys.argv[2]).read()
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1)) / 2**20
s = j.get("sparse", {})
print(f"{j['lattice']} {j['sampler']}: band {j['sparse_wall_s']:.2f} s wall ({j['sparse_cpu_s']:.1f} s CPU, kernels "
      f"{j['sparse_kernel_s']:.3f} s), with load {j['sparse_wall_with_load_s']:.2f} s; active blocks {j['active_blocks']}, "
      f"band points {j['band_points']}, memory {s.get('memory_bytes', 0) / 2**30:.2f} GiB, peak RSS {rss:.1f} GiB")
PY
}
for res in $RESOLUTIONS; do
    [ "$BENCH" = 1 ] || break
    for backend in ${BACKENDS:-cuda cpu}; do
        log "bench_sparse_band sparse-distance dragon.obj $res 3 cc $backend"
        /usr/bin/time -v $B/tests/benchmarks/bench_sparse_band sparse-distance "$MESH" "$res" 3 cc $backend \
            > "$OUT/bench-$res-$backend.json" 2> "$OUT/time-$res-$backend.txt"
        echo "exit $?" | tee -a "$OUT/summary.txt"
        row "$OUT/bench-$res-$backend.json" "$OUT/time-$res-$backend.txt" || tail -5 "$OUT/time-$res-$backend.txt"
    done
done
# End to end at the largest resolution: 3 spacings of the fitted lattice (margin 0.1).
res=${RESOLUTIONS##* }
W=$(python3 -c "
v = [[float(x) for x in l.split()[1:4]] for l in open('$MESH') if l.startswith('v ')]
extent = max(max(p[a] for p in v) - min(p[a] for p in v) for a in range(3))
print(repr(3 * extent * 1.2 / ($res - 1)))")
work=$PWD/huge-band-out
# 1. the .nvdb alone (no field file: sdf-sample's --out left out), against dd of its bytes;
# 2. the sparse field file ($DTYPE) beside it.
for files in ${FILES:-nvdb field+nvdb}; do
    rm -rf "$work" && mkdir -p "$work"
    out=()
    [ "$files" = nvdb ] || out=(--layout sparse --out "$work/band.json")
    log "sdf-sample $MESH --resolution $res --band $W --sparse --channels distance --dtype $DTYPE --nvdb ${out[*]} (cuda)"
    /usr/bin/time -v $B/bin/sdf-sample "$MESH" --resolution "$res" --band "$W" --sparse --channels distance --dtype "$DTYPE" \
        --backend cuda --quiet --nvdb "$work/band.nvdb" "${out[@]}" > "$OUT/sdf-sample-$files.txt" 2> "$OUT/sdf-sample-time-$files.txt"
    echo "exit $?" | tee -a "$OUT/summary.txt"
    cat "$OUT/sdf-sample-$files.txt" | tee -a "$OUT/summary.txt"
    grep -E "Elapsed|Maximum resident|User time|System time" "$OUT/sdf-sample-time-$files.txt" | tee -a "$OUT/summary.txt"
    bytes=$(du -cb "$work" | tail -1 | cut -f1)
    echo "files: $bytes bytes ($(du -sh "$work" | cut -f1))" | tee -a "$OUT/summary.txt"
    rm -rf "$work" && mkdir -p "$work"
    log "dd of $bytes bytes with fsync (the bytes' own write)"
    dd if=/dev/zero of="$work/dd" bs=64M count=$(( (bytes + 67108863) / 67108864 )) conv=fsync 2>&1 | tail -1 | tee -a "$OUT/summary.txt"
    rm -rf "$work"
done
log "done"
