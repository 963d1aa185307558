# Session 53, run 5 (the final tree: b4cd820's code, the cuda_bvh_points_* tests added):
# ctest -L gpu on two GPUs and on one.
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
NG=$(nvidia-smi -L | wc -l); nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
(cd build-gpu && timeout 200 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-all.log 2>&1; echo "all GPUs ($NG): exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*|cuda_bvh_points" $OUT/ctest-gpu-all.log | head -12)
(cd build-gpu && CUDA_VISIBLE_DEVICES=0 timeout 200 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-one.log 2>&1; echo "one GPU: exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*" $OUT/ctest-gpu-one.log | head -8)
grep -h "re-ranked" build-gpu/Testing/Temporary/LastTest.log 2>/dev/null | head -3
