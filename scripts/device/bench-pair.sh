#!/usr/bin/env bash
# A before/after benchmark round on one machine: the same benchmarks from two build trees,
# run in the order A B B A per round (so that drift of the machine falls on both sides
# alike; ORDER=AB runs A B), the medians per benchmark and side in $OUT/bench-pair.txt with B/A.
#   scripts/device/bench-pair.sh BUILD_A BUILD_B [rounds]    (carry: data)
# Benchmarks: the BVH searches (bench_bvh: the CPU's three kernels on all threads with the
# pseudonormal and the winding sign, the packet kernel on one thread; every CUDA kernel in
# float, the default warp kernel in double, on 16.8M near-surface points and in a band), the
# scalar winding-number walks (bench_winding), and sdf-sample's kernel time on dragon-legacy
# (the winding sign's exact stage and ladder: CPU packets, GPU warps). Each step's start is
# logged in $OUT/steps.log.
set -uo pipefail
cd "$(dirname "$0")/../.."
A=$1 B=$2 ROUNDS=${3:-2}
OUT=${OUT:-$PWD/bench-out}
mkdir -p "$OUT"
export SDF_DATA_PATH=$PWD/data/meshes
BVH_FILTER=${BVH_FILTER:-'^BM_CpuBvh/(dragon|dragon_legacy)/res:128/threads:0/|^BM_CpuBvh/dragon/res:64/threads:1/kernel:0|^BM_CudaBvh/dragon/res:128/kernel:[0-4]/double:0|^BM_CudaBvh/dragon/res:(128|256)/kernel:3/double:1|^BM_CudaBvh/dragon/res:256/kernel:3/double:0|^BM_CudaBvhPoints/dragon/points:16777216/gaussian:1/kernel:3|^BM_CudaBvhBand/dragon/res:256/band_spacings:2/kernel:3'}
WINDING_FILTER=${WINDING_FILTER:-'^BM_WindingFast/64/1/20/2|^BM_WindingCertified/64/1/40/2'}

run_side() {  # side build round
    local side=$1 dir=$2 r=$3
    echo "$(date +%T) $side $r bench_bvh" >> "$OUT/steps.log"
    "$dir/tests/benchmarks/bench_bvh" --benchmark_filter="$BVH_FILTER" --benchmark_format=json \
        --benchmark_out="$OUT/bvh-$side-$r.json" > /dev/null 2>> "$OUT/stderr-$side.log"
    echo "$(date +%T) $side $r bench_winding" >> "$OUT/steps.log"
    "$dir/tests/benchmarks/bench_winding" --benchmark_filter="$WINDING_FILTER" --benchmark_format=json \
        --benchmark_out="$OUT/winding-$side-$r.json" > /dev/null 2>> "$OUT/stderr-$side.log"
    for run in "cpu 128" "cuda 256"; do
        set -- $run
        local name="sample-$1-$2-$side-$r"
        echo "$(date +%T) $side $r sdf-sample $1 $2" >> "$OUT/steps.log"
        "$dir/bin/sdf-sample" dragon-legacy.obj --resolution "$2" --backend "$1" --channels distance --quiet \
            --out "/tmp/$name.json" >> "$OUT/stderr-$side.log" 2>&1
        cp "/tmp/$name.json" "$OUT/$name.json" 2> /dev/null
        rm -f /tmp/"$name".*
    done
}

for r in $(seq "$ROUNDS"); do
    echo "== $(date +%T) round $r"
    run_side A "$A" "$r"; run_side B "$B" "$r"
    [ "${ORDER:-ABBA}" = AB ] || { run_side B "$B" "$r.2"; run_side A "$A" "$r.2"; }
done

python3 - "$OUT" > "$OUT/bench-pair.txt" <<'EOF'
import glob, json, os, statistics, sys
out = sys.argv[1]
times = {}  # (name, side) -> [ms]
for path in glob.glob(os.path.join(out, "*.json")):
    base = os.path.basename(path)
    side = base.split("-")[-2]
    with open(path) as f:
        d = json.load(f)
    if base.startswith("sample-"):
        name = "sdf-sample dragon-legacy " + " ".join(base.split("-")[1:3]) + " (kernel)"
        times.setdefault((name, side), []).append(d["timings_seconds"]["kernel"] * 1e3)
        continue
    for b in d.get("benchmarks", []):
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        if "error_occurred" in b and b["error_occurred"]:
            continue
        unit = {"ms": 1.0, "us": 1e-3, "ns": 1e-6, "s": 1e3}[b.get("time_unit", "ns")]
        name = b["run_name"] if "run_name" in b else b["name"]
        times.setdefault((name, side), []).append(b["real_time"] * unit)
names = sorted({n for n, _ in times})
print("%-90s %12s %12s %8s" % ("benchmark (median of runs, ms)", "A", "B", "B/A"))
for n in names:
    a, b = times.get((n, "A")), times.get((n, "B"))
    if not a or not b:
        continue
    ma, mb = statistics.median(a), statistics.median(b)
    print("%-90s %12.3f %12.3f %8.3f" % (n, ma, mb, mb / ma))
EOF
cat "$OUT/bench-pair.txt"
