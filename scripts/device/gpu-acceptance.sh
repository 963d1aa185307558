#!/usr/bin/env bash
# The GPU acceptance run of issues 3, 5, 6 and 7 on a lent machine (device tool):
# builds, runs the GPU tests, compute-sanitizer, the kernel benchmarks, the GPU render timing
# and the GPU studies. Everything lands in /tmp/gpu-run, packed into $OUT/gpu-run.tgz after
# every step, so a run cut short still returns what it finished.
#   carry: .gpu-prefix data
set -uo pipefail
cd "$(dirname "$0")/../.."
FINAL_OUT=${OUT:-$PWD/gpu-out}
export OUT=/tmp/gpu-run
mkdir -p "$OUT" "$FINAL_OUT"
export SDF_DATA_PATH=$PWD/data/meshes
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
B=build-gpu
pack() { tar czf "$FINAL_OUT/gpu-run.tgz.part" -C /tmp gpu-run && mv "$FINAL_OUT/gpu-run.tgz.part" "$FINAL_OUT/gpu-run.tgz"; }
step() { echo "== $(date +%T) $1"; }

scripts/device/gpu-session.sh build || exit 1
pack
step "GPU tests"
(cd $B && ctest -L gpu --output-on-failure -V > "$OUT/ctest-gpu.log" 2>&1; echo "ctest -L gpu exit $?") | tee -a "$OUT/summary.txt"
grep -E "^[0-9]+/[0-9]+ Test|tests passed|FAILED|kernel .* ms" "$OUT/ctest-gpu.log" | tee -a "$OUT/summary.txt"
pack
step "compute-sanitizer"
for t in "cuda_sampler_test --gtest_filter=*Splitting*:*PointQueries*" "cuda_bvh_test --gtest_filter=*Slabs*:*PointQueries*" \
         "raycast_gpu_test --gtest_filter=*AgreesWith*"; do
    compute-sanitizer --tool memcheck --error-exitcode 3 $B/tests/gpu/$t > "$OUT/sanitizer-${t%% *}.txt" 2>&1
    echo "compute-sanitizer ${t%% *}: exit $? $(grep 'ERROR SUMMARY' "$OUT/sanitizer-${t%% *}.txt")" | tee -a "$OUT/summary.txt"
done
pack
step "kernel benchmarks"
$B/tests/benchmarks/bench_cuda_sampler --benchmark_counters_tabular=true --benchmark_min_time=0.3s \
    --benchmark_out="$OUT/bench_cuda_sampler.json" --benchmark_out_format=json > "$OUT/bench_cuda_sampler.txt" 2>&1
grep -E "^(tuned|thesis)/" "$OUT/bench_cuda_sampler.txt" | awk '{print $1, $2, $3, $7}' | tee -a "$OUT/summary.txt"
$B/tests/benchmarks/bench_bvh --benchmark_filter='Cuda' --benchmark_counters_tabular=true \
    --benchmark_out="$OUT/bench_bvh.json" --benchmark_out_format=json > "$OUT/bench_bvh.txt" 2>&1
grep -E "^BM_Cuda" "$OUT/bench_bvh.txt" | tee -a "$OUT/summary.txt"
pack
step "1024^2 BCC cubic render on the GPU"
$B/bin/sdf-render dragon.obj --lattice bcc --resolution 64,64,128 --interpolator bcc_cubic --derivatives true \
    --view dragon_side --size 1024 --backend cuda --repeat 20 --out "$OUT/dragon_bcc_1024.ppm" --overwrite 2>&1 | tee "$OUT/render.txt" | tail -3
pack
for cfg in configs/gpu_kernels.json configs/dragon.json configs/speedup.json configs/peers.json; do
    step "run-experiment $cfg"
    $B/bin/run-experiment "$cfg" --output-root "$OUT/results" --quiet > "$OUT/$(basename "$cfg" .json).log" 2>&1
    echo "$cfg exit $?" | tee -a "$OUT/summary.txt"
    tail -4 "$OUT/$(basename "$cfg" .json).log"
    pack
done
step "full ctest"
(cd $B && ctest -j 8 > "$OUT/ctest-all.log" 2>&1; echo "ctest exit $?") | tee -a "$OUT/summary.txt"
tail -12 "$OUT/ctest-all.log"
pack
step done
