#!/usr/bin/env bash
# One GPU check of the whole tree on a lent machine (device tool), for a change that moved or
# touched kernels: builds with CUDA and warnings as errors, runs every GPU test, every CPU test
# there too, compute-sanitizer on the GPU tests' split/point-query cases, and the CI smoke study
# from a portable CPU build (whose field checksums must equal those of any other CPU target).
#   carry: .gpu-prefix data        steps: build gputest test python sanitize asan portable bench-filters stream
# Output under $OUT: summary.txt and the logs.
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-$PWD/gpu-out}
mkdir -p "$OUT"
PREFIX=$PWD/.gpu-prefix/root/usr
scripts/device/unpack-debs  # CGAL, Boost's headers, GMP, MPFR: carried as .deb files
export LD_LIBRARY_PATH=$PREFIX/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes
B=build-gpu
log() { echo "== $(date +%T) $*" | tee -a "$OUT/summary.txt"; }
# The copy has no .git: SDF_SOURCE_COMMIT=<sha>[-dirty] is recorded as the runs' commit.
cmake_common=(-G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PREFIX" -DSDF_SOURCE_COMMIT="${SDF_SOURCE_COMMIT:-}")
# The lent machines' python3 (with PyTorch, CuPy, JAX) has pybind11 from pip, not Debian's CMake
# package: point CMake at it, so that the module and its GPU-tensor tests are built there.
if python3 -m pybind11 --cmakedir > /dev/null 2>&1; then
    cmake_common+=(-Dpybind11_DIR="$(python3 -m pybind11 --cmakedir)" -DPython3_EXECUTABLE="$(command -v python3)")
fi
[ -f /usr/include/openssl/evp.h ] || cmake_common+=(-DOPENSSL_ROOT_DIR="$PREFIX" -DOPENSSL_INCLUDE_DIR="$PREFIX/include"
    -DOPENSSL_CRYPTO_LIBRARY="$PREFIX/lib/x86_64-linux-gnu/libcrypto.so.3"
    -DCMAKE_CXX_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu" -DCMAKE_CUDA_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu")

for step in "$@"; do case "$step" in
build)
    log "configure + build (CUDA, warnings as errors)"
    nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee -a "$OUT/summary.txt"
    cmake -S . -B $B "${cmake_common[@]}" -DSDF_ENABLE_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 -DSDF_WARNINGS_AS_ERRORS=ON \
        > "$OUT/configure.log" 2>&1 || { tail -30 "$OUT/configure.log"; exit 1; }
    grep "sdf:" "$OUT/configure.log" | tee -a "$OUT/summary.txt"
    cmake --build $B -j "$(nproc)" -- -k 0 > "$OUT/build.log" 2>&1 || { grep -E "error|warning|FAILED" "$OUT/build.log" | head -40; exit 1; }
    log "built" ;;
gputest)
    log "GPU tests"
    (cd $B && ctest -L gpu --output-on-failure > "$OUT/ctest-gpu.log" 2>&1; echo "ctest -L gpu exit $?") | tee -a "$OUT/summary.txt"
    grep -E "Test +#|tests passed" "$OUT/ctest-gpu.log" | tee -a "$OUT/summary.txt" ;;
test)
    log "all tests"
    (cd $B && ctest -j 8 --output-on-failure > "$OUT/ctest-all.log" 2>&1; echo "ctest exit $?") | tee -a "$OUT/summary.txt"
    grep -E "tests passed|\(Failed\)|\(Skipped\)|Not Run" "$OUT/ctest-all.log" | tee -a "$OUT/summary.txt" ;;
python)
    log "Python module: query() = sdf-query on the GPU, bit for bit (tests/python_module)"
    if [ -f $B/CTestTestfile.cmake ] && grep -q "Python module ON" "$OUT/configure.log" 2>/dev/null; then
        PYTHONPATH=$B/python SDF_QUERY=$B/bin/sdf-query SDF_EVAL=$B/bin/sdf-eval RUN_EXPERIMENT=$B/bin/run-experiment \
            python3 -m pytest -q -rs -p no:cacheprovider tests/python_module > "$OUT/pytest-module.log" 2>&1
        echo "pytest tests/python_module exit $?" | tee -a "$OUT/summary.txt"
        grep -E "passed|failed|SKIPPED" "$OUT/pytest-module.log" | tee -a "$OUT/summary.txt"
    else
        echo "no Python module in this build (pybind11, python3-dev or numpy missing)" | tee -a "$OUT/summary.txt"
    fi ;;
sanitize)
    log "compute-sanitizer"
    for t in "cuda_sampler_test --gtest_filter=*Splitting*:*PointQueries*" "cuda_bvh_test --gtest_filter=*Slabs*:*PointQueries*:*NarrowBand*" \
             "raycast_gpu_test"; do
        compute-sanitizer --tool memcheck --error-exitcode 3 $B/tests/gpu/$t > "$OUT/sanitizer-${t%% *}.txt" 2>&1
        echo "compute-sanitizer ${t%% *}: exit $? $(grep 'ERROR SUMMARY' "$OUT/sanitizer-${t%% *}.txt")" | tee -a "$OUT/summary.txt"
    done ;;
asan)
    # scripts/test --sanitize with this machine's cores and the carried prefix: ASan + UBSan
    # build of the CPU code (no CUDA, benchmarks or Python), then the CPU tests, every report fatal.
    log "AddressSanitizer + UndefinedBehaviorSanitizer: the CPU tests"
    flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
    san_common=("${cmake_common[@]}")
    for i in "${!san_common[@]}"; do case "${san_common[$i]}" in -DCMAKE_BUILD_TYPE=*) san_common[$i]=-DCMAKE_BUILD_TYPE=RelWithDebInfo ;;
        -DCMAKE_CXX_FLAGS=*) flags="$flags ${san_common[$i]#-DCMAKE_CXX_FLAGS=}"; unset 'san_common[$i]' ;; -DCMAKE_CUDA_FLAGS=*) unset 'san_common[$i]' ;; esac; done
    cmake -S . -B build-asan "${san_common[@]}" -DSDF_ENABLE_CUDA=OFF -DSDF_BUILD_BENCHMARKS=OFF -DSDF_BUILD_PYTHON=OFF \
        -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" > "$OUT/configure-asan.log" 2>&1 &&
        cmake --build build-asan -j "$(nproc)" > "$OUT/build-asan.log" 2>&1 || { grep -E "error|FAILED" "$OUT/build-asan.log" | head -20; exit 1; }
    # As scripts/test --sanitize: the MPI tests without the leak check (Open MPI's unloaded plugins).
    asan="abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
    (cd build-asan && export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" &&
        ASAN_OPTIONS="detect_leaks=1:$asan" ctest --output-on-failure -L cpu -LE mpi -j "$(nproc)" > "$OUT/ctest-asan.log" 2>&1
        echo "ctest -L cpu -LE mpi (ASan + UBSan + LSan) exit $?"
        ASAN_OPTIONS="detect_leaks=0:$asan" ctest --output-on-failure -L mpi -j "$(nproc)" >> "$OUT/ctest-asan.log" 2>&1
        echo "ctest -L mpi (ASan + UBSan) exit $?") | tee -a "$OUT/summary.txt"
    grep -E "tests passed|\(Failed\)|\(Subprocess|Not Run|Timeout" "$OUT/ctest-asan.log" | tee -a "$OUT/summary.txt" ;;
portable)
    log "portable CPU build: CI smoke field checksums"
    cmake -S . -B build-portable "${cmake_common[@]}" -DSDF_ENABLE_CUDA=OFF -DSDF_BUILD_TESTS=OFF -DSDF_BUILD_BENCHMARKS=OFF \
        > "$OUT/configure-portable.log" 2>&1 && cmake --build build-portable -j "$(nproc)" --target run-experiment \
        > "$OUT/build-portable.log" 2>&1 || { tail -20 "$OUT/build-portable.log"; exit 1; }
    grep "sdf: CPU target" "$OUT/configure-portable.log" | tee -a "$OUT/summary.txt"
    rm -rf /tmp/smoke && build-portable/bin/run-experiment configs/ci_smoke.json --output-root /tmp/smoke/results \
        --cache-dir /tmp/smoke/cache --quiet > "$OUT/smoke.log" 2>&1
    (cd /tmp/smoke && find cache -name '*.raw' | sort | xargs sha256sum | sed 's#cache/fields/../##') | tee "$OUT/smoke-portable.sha256" ;;
bench-filters)
    # Issue 17: every filter's evaluation speed through the ray caster on the GPU (CUDA events),
    # and the CPU evaluation benchmark of every filter on this machine's CPU for comparison.
    log "bench_raycast_filters (GPU), bench_reconstruction (CPU)"
    $B/tests/benchmarks/bench_raycast_filters --benchmark_filter=/cuda --benchmark_counters_tabular=true \
        --benchmark_out="$OUT/bench_raycast_filters.json" --benchmark_out_format=json > "$OUT/bench_raycast_filters.txt" 2>&1
    echo "bench_raycast_filters exit $?" | tee -a "$OUT/summary.txt"
    $B/tests/benchmarks/bench_reconstruction --benchmark_filter='BM_Evaluate<float>' --benchmark_counters_tabular=true \
        --benchmark_out="$OUT/bench_reconstruction.json" --benchmark_out_format=json > "$OUT/bench_reconstruction.txt" 2>&1
    echo "bench_reconstruction exit $?" | tee -a "$OUT/summary.txt" ;;
stream)
    # Issue 14: sdf-sample on the GPU. Many slabs equal one slab byte for byte (CC, BCC, with and
    # without a band; the mesh as STREAM_MESH, default the dragon), then scripts/scaling-run from
    # 32^3 to 1024^3 CC (STREAM_MAX) with an 8 GiB budget, fields in STREAM_FIELDS (17 GB at 1024^3).
    M=${STREAM_MESH:-data/meshes/dragon.obj}
    S=${STREAM_FIELDS:-/tmp/stream-fields}
    log "sdf-sample --backend cuda: many slabs = one slab, byte for byte ($M)"
    rm -rf "$S" && mkdir -p "$S"
    while read -r lattice res band; do
        common=("$M" --backend cuda --lattice "$lattice" --resolution "$res" --band "$band" --quiet)
        $B/bin/sdf-sample "${common[@]}" --out "$S/one.json" >> "$OUT/stream-check.log" 2>&1
        # The .vdb too where the build has OpenVDB (the lent machines have none).
        $B/bin/sdf-sample "${common[@]}" --max-planes-per-slab 7 --memory-budget 4GiB --vdb "$S/many.vdb" --out "$S/many.json" \
            >> "$OUT/stream-check.log" 2>&1 ||
            $B/bin/sdf-sample "${common[@]}" --max-planes-per-slab 7 --memory-budget 4GiB --out "$S/many.json" \
            >> "$OUT/stream-check.log" 2>&1
        for ch in distance gradient closest_triangle; do
            cmp -s "$S/one.$ch.raw" "$S/many.$ch.raw" && r=same || r=DIFFERENT
            echo "$lattice $res band $band $ch: $r" | tee -a "$OUT/summary.txt"
        done
        grep -o '"slabs": [0-9]*' "$S/many.json" | head -1 | tee -a "$OUT/summary.txt"
        rm -f "$S"/one.* "$S"/many.*
    done <<'LIST'
cc 128 0
cc 128 0.004
bcc 64 0
bcc 64 0.004
LIST
    log "scripts/scaling-run --backend cuda, CC 32^3 .. ${STREAM_MAX:-1024}^3, budget 8 GiB"
    scripts/scaling-run "$M" --backend cuda --max-resolution "${STREAM_MAX:-1024}" --memory-budget 8GiB \
        --fields "$S" --results "$OUT/scaling" --sdf-sample $B/bin/sdf-sample 2>&1 | tee -a "$OUT/summary.txt"
    rm -rf "$S" ;;
*) echo "unknown step $step"; exit 2 ;;
esac; done
log done
