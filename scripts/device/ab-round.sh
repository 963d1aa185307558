#!/usr/bin/env bash
# One device call of a before/after round (device tool): unpacks the carried prefix, builds two
# source trees side by side (bench_bvh, bench_winding, sdf-sample; with `gputest` also every
# GPU test of the second), runs bench-pair.sh on them and then the second's GPU tests. Results
# come back as $OUT/all.tgz (the device returns at most 8 files).
#   scripts/device/ab-round.sh OLD_SRC OLD_SHA NEW_SRC NEW_SHA "ROUNDS" [gputest]
#   carry: .gpu-prefix data and OLD_SRC (a `git archive` of the old commit, e.g. build-src-<sha>)
# Builds go to build-old-gpu and build-new-gpu at the root (outside carried paths, which a
# call replaces); remove them first on a machine still warm from another round. WERROR=OFF
# for old trees that a newer GCC warns on; BVH_FILTER and WINDING_FILTER pass to bench-pair.sh.
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-$PWD/out}; mkdir -p "$OUT"
PREFIX=$PWD/.gpu-prefix/root/usr
scripts/device/unpack-debs > "$OUT/unpack.log" 2>&1
export LD_LIBRARY_PATH=$PREFIX/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader > "$OUT/gpu.txt"; nproc >> "$OUT/gpu.txt"
common=(-G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PREFIX" -DSDF_ENABLE_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 -DSDF_WARNINGS_AS_ERRORS=${WERROR:-ON})
[ -f /usr/include/openssl/evp.h ] || common+=(-DOPENSSL_ROOT_DIR="$PREFIX" -DOPENSSL_INCLUDE_DIR="$PREFIX/include"
    -DOPENSSL_CRYPTO_LIBRARY="$PREFIX/lib/x86_64-linux-gnu/libcrypto.so.3"
    -DCMAKE_CXX_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu" -DCMAKE_CUDA_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu")
OLD_SRC=$1 OLD_SHA=$2 NEW_SRC=$3 NEW_SHA=$4 PAIR=$5 GPUTEST=${6:-}
targets="bench_bvh bench_winding sdf-sample"
gtargets=""
[ -n "$GPUTEST" ] && gtargets="$(grep -o 'sdf_add_test([a-z_]*' tests/gpu/CMakeLists.txt | sed 's/sdf_add_test(//') multi_gpu_test experiments_gpu_test run-experiment"
build() {  # src sha dir extra-targets
    cmake -S "$1" -B "$3" "${common[@]}" -DSDF_SOURCE_COMMIT="$2" > "$OUT/configure-$3.log" 2>&1 || { tail -20 "$OUT/configure-$3.log"; return 1; }
    cmake --build "$3" -j 16 --target $targets $4 > "$OUT/build-$3.log" 2>&1 || { grep -E "error|FAILED" "$OUT/build-$3.log" | head -20; return 1; }
}
echo "$(date +%T) build" | tee -a "$OUT/log.txt"
build "$OLD_SRC" "$OLD_SHA" build-old-gpu "" & p1=$!
build "$NEW_SRC" "$NEW_SHA" build-new-gpu "$gtargets" & p2=$!
wait $p1; r1=$?; wait $p2; r2=$?
echo "$(date +%T) built $r1 $r2" | tee -a "$OUT/log.txt"
if [ "$r1" = 0 ] && [ "$r2" = 0 ] && [ -n "$PAIR" ]; then
    OUT=$OUT/pair scripts/device/bench-pair.sh build-old-gpu build-new-gpu $PAIR > "$OUT/pair.log" 2>&1
    echo "$(date +%T) pair done" | tee -a "$OUT/log.txt"
fi
if [ -n "$GPUTEST" ] && [ "$r2" = 0 ]; then
    (cd build-new-gpu && ctest -L gpu --output-on-failure > "$OUT/ctest-gpu.log" 2>&1; echo "ctest -L gpu exit $?") | tee -a "$OUT/log.txt"
    grep -E "Test +#|tests passed" "$OUT/ctest-gpu.log" >> "$OUT/log.txt"
fi
echo "$(date +%T) end" >> "$OUT/log.txt"
tar -czf /tmp/all.tgz -C "$OUT" . 2>/dev/null; rm -rf "$OUT"/*; mv /tmp/all.tgz "$OUT/all.tgz"
