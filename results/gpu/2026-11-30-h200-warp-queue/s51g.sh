# Session 51, run 7 (final tree a11bd85): GPU tests on two GPUs and on one, the Python module's
# tests (CUDA cases), compute-sanitizer on the point queries, a racecheck of the warp search.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-a11bd85}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt; cp $O/configure.log $OUT/
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
NG=$(nvidia-smi -L | wc -l); nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
(cd build-gpu && timeout 200 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-all.log 2>&1; echo "all GPUs ($NG): exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*" $OUT/ctest-gpu-all.log | head -8)
(cd build-gpu && CUDA_VISIBLE_DEVICES=0 timeout 200 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-one.log 2>&1; echo "one GPU: exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*" $OUT/ctest-gpu-one.log | head -8)
OUT=$OUT timeout 150 scripts/device/gpu-check.sh python 2>&1 | tail -4
timeout 100 compute-sanitizer --tool memcheck --error-exitcode 3 build-gpu/tests/gpu/cuda_bvh_test --gtest_filter=*PointQueries*:*Slabs* > $OUT/sanitizer-memcheck.txt 2>&1; echo "memcheck exit $? $(grep 'ERROR SUMMARY' $OUT/sanitizer-memcheck.txt)"
timeout 100 compute-sanitizer --tool racecheck --error-exitcode 3 build-gpu/tests/gpu/cuda_bvh_test --gtest_filter=*PointQueries* > $OUT/sanitizer-racecheck.txt 2>&1; echo "racecheck exit $? $(grep 'RACECHECK SUMMARY\|ERROR SUMMARY' $OUT/sanitizer-racecheck.txt)"
