# Session 50, run 5: the final tree (listed search at 6 blocks for one or two points a thread): GPU tests on two GPUs and one; the query once more.
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -2 $O/summary.txt; cp $O/summary.txt $OUT/build-summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
NG=$(nvidia-smi -L | wc -l); nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
(cd build-gpu && timeout 100 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-all.log 2>&1; echo "all GPUs ($NG): exit $?"; grep -E "tests passed|Skipped|\(Failed\)" $OUT/ctest-gpu-all.log | head -8)
(cd build-gpu && CUDA_VISIBLE_DEVICES=0 timeout 100 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-one.log 2>&1; echo "one GPU: exit $?"; grep -E "tests passed|Skipped|\(Failed\)" $OUT/ctest-gpu-one.log | head -8)
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O
CUDA_VISIBLE_DEVICES=0 timeout 120 python3 data/s50-variants.py $M $O listed 2>&1 | grep -v "Warning\|^  " | tee $OUT/variants.log
