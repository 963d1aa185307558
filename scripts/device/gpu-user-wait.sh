#!/usr/bin/env bash
# What a user waits for on the GPU machine, beside the kernel time (issue 23's table), for one
# build tree: sdf-sample of the dragon at 1024^3 CC (float32 distance + gradient, 8 GiB budget)
# against `dd` writing the same bytes to the same disk (scripts/scaling-run), and one call of
# the point query on 16.8M points (BM_CudaBvhPoints: the call's wall time beside the device
# time of sort, search and finalize), plus the lattice kernels (BM_CudaBvh warp, BM_CudaBrute).
#   scripts/device/gpu-user-wait.sh BUILD_DIR LABEL [RESOLUTIONS]
# Run it for the baseline tree and the new one in the same call, so that both numbers come
# from the same card. Output under $OUT/user-wait-LABEL/; a summary line per row on stdout.
set -uo pipefail
cd "$(dirname "$0")/../.."
B=$1
LABEL=$2
RESOLUTIONS=${3:-1024}
OUT=${OUT:-$PWD/gpu-out}
DIR=$OUT/user-wait-$LABEL
mkdir -p "$DIR"
export SDF_DATA_PATH=${SDF_DATA_PATH:-$PWD/data/meshes}
MESH=$SDF_DATA_PATH/dragon.obj
FIELDS=${USER_WAIT_FIELDS:-/tmp/user-wait-fields}
rm -rf "$FIELDS" && mkdir -p "$FIELDS"

echo "== $LABEL: sdf-sample dragon CC $RESOLUTIONS (scaling-run, with dd)"
python3 scripts/scaling-run "$MESH" --backend cuda --resolutions "$RESOLUTIONS" --memory-budget 8GiB \
    --fields "$FIELDS" --results "$DIR/scaling" --sdf-sample "$B/bin/sdf-sample" > "$DIR/scaling.log" 2>&1
grep -E "^N = |rror" "$DIR/scaling.log"
rm -rf "$FIELDS"

echo "== $LABEL: point queries and lattice kernels (bench_bvh, bench on the dragon)"
"$B/tests/benchmarks/bench_bvh" --benchmark_filter='BM_CudaBvhPoints|BM_CudaBvh/dragon/res:(128|256)/kernel:3/double:0|BM_CudaBrute/dragon' \
    --benchmark_counters_tabular=true --benchmark_out="$DIR/bench_bvh.json" --benchmark_out_format=json > "$DIR/bench_bvh.txt" 2>&1
grep -E "^BM_" "$DIR/bench_bvh.txt" | grep -v -E "_(mean|median|stddev|cv) " | cut -c1-160
