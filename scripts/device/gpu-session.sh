#!/usr/bin/env bash
# Builds the project on a GPU machine without network access and runs the GPU tests,
# benchmarks and experiments given as arguments. Used with the device tool:
#   carry: .gpu-prefix (Debian tinyobjloader, CLI11, OpenSSL unpacked) and data (meshes; and
#          data/peers, a copy of ../shared/peers, for the FCPW and cuBQL peers: CMake finds it)
#   scripts/device/gpu-session.sh build test bench "experiment configs/x.json" ...
# Everything worth keeping is written under $OUT (default: ./gpu-out).
# The copy has no .git: pass the commit in, SDF_SOURCE_COMMIT=<sha>[-dirty] scripts/device/...,
# and every run's provenance records it (docs/gpu-notes.md).
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-$PWD/gpu-out}
mkdir -p "$OUT"
PREFIX=$PWD/.gpu-prefix/root/usr
scripts/device/unpack-debs  # CGAL, Boost's headers, GMP, MPFR: carried as .deb files
export LD_LIBRARY_PATH=$PREFIX/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes
BUILD=${BUILD:-build-gpu}

log() { echo "== $(date +%T) $*"; }

build() {
    local extra=()
    if [ ! -f /usr/include/openssl/evp.h ]; then
        extra+=(-DOPENSSL_ROOT_DIR="$PREFIX" -DOPENSSL_INCLUDE_DIR="$PREFIX/include"
                -DOPENSSL_CRYPTO_LIBRARY="$PREFIX/lib/x86_64-linux-gnu/libcrypto.so.3"
                -DCMAKE_CXX_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu"
                -DCMAKE_CUDA_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu")
    fi
    log "configure"
    cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSDF_ENABLE_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 \
        -DCMAKE_PREFIX_PATH="$PREFIX" -DSDF_SOURCE_COMMIT="${SDF_SOURCE_COMMIT:-}" "${extra[@]}" > "$OUT/configure.log" 2>&1 || { tail -40 "$OUT/configure.log"; return 1; }
    grep -E "sdf:|sdf peers:" "$OUT/configure.log"
    log "build"
    # BUILD_TARGETS (space-separated) limits the build, e.g. to the GPU tests and tools.
    cmake --build "$BUILD" -j "$(nproc)" ${BUILD_TARGETS:+--target $BUILD_TARGETS} > "$OUT/build.log" 2>&1 ||
        { grep -E "error|FAILED" "$OUT/build.log" | head -40; return 1; }
    log "built"
}

run_step() {
    case "$1" in
        build) build ;;
        test) log "ctest (all)"; (cd "$BUILD" && ctest --output-on-failure -j 4 2>&1 | tee "$OUT/ctest.log" | tail -40) ;;
        gputest) log "ctest -L gpu"; (cd "$BUILD" && ctest -L gpu --output-on-failure -V 2>&1 | tee "$OUT/ctest-gpu.log" | grep -vE "^[0-9]+: \[ +(RUN|OK) " | tail -80) ;;
        bench) log "bench_cuda_sampler"; "$BUILD/tests/benchmarks/bench_cuda_sampler" --benchmark_counters_tabular=true \
                   --benchmark_out="$OUT/bench_cuda_sampler.json" --benchmark_out_format=json 2>&1 | tee "$OUT/bench_cuda_sampler.txt" ;;
        cpubench) log "bench_cpu_sampler"; "$BUILD/tests/benchmarks/bench_cpu_sampler" --benchmark_counters_tabular=true 2>&1 | tail -8 ;;
        sanitize) log "compute-sanitizer"; compute-sanitizer --tool memcheck --error-exitcode 3 "$BUILD/tests/gpu/cuda_sampler_test" \
                      --gtest_filter='*Splitting*:*PointQueries*' 2>&1 | tee "$OUT/compute-sanitizer.txt" | tail -15 ;;
        sass) log "SASS of the CUDA sampler"; cuobjdump -sass "$BUILD/cuda/CMakeFiles/sdf_cuda.dir/brute_force/cuda_sampler.cu.o" > "$OUT/sampler.sass" 2>&1;
              cuobjdump -res-usage "$BUILD/cuda/CMakeFiles/sdf_cuda.dir/brute_force/cuda_sampler.cu.o" 2>&1 | grep -A1 tuned | head -20 ;;
        profile) log "ncu: tuned kernel on the dragon 64^3";
                 ncu --clock-control none -k regex:nearest_triangle_tuned -c 2 --section SchedulerStats --section WarpStateStats \
                     --section InstructionStats --section Occupancy --section ComputeWorkloadAnalysis \
                     "$BUILD/tests/benchmarks/bench_cuda_sampler" --benchmark_filter='^tuned/dragon_legacy/64x64x64cc' \
                     --benchmark_min_time=0.01 > "$OUT/ncu.txt" 2>&1; grep -E "Issue|Executed Ipc|Warp Cycles|Stall|Occupancy|Registers|Instructions" "$OUT/ncu.txt" | head -40 ;;
        experiment\ *) local cfg=${1#experiment }; log "run-experiment $cfg";
                       "$BUILD/bin/run-experiment" "$cfg" --output-root "$OUT" --quiet 2>&1 | tee -a "$OUT/experiments.log" ;;
        *) echo "unknown step: $1"; return 2 ;;
    esac
}

nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.sm,clocks.max.sm --format=csv 2>&1 | tee "$OUT/gpu.txt"
status=0
for step in "$@"; do run_step "$step" || { status=$?; log "step '$step' failed ($status)"; [ "$step" = build ] && exit $status; }; done
exit $status
