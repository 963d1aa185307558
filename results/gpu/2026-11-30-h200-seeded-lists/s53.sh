# Session 53, run 1 (fde3936 + leaf/radius knobs): GPU tests on two GPUs and one (fde3936 was
# never run on a GPU), then the device tree's leaf size and PLOC radius against the queries.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s53}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt; cp $O/configure.log $OUT/
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
NG=$(nvidia-smi -L | wc -l); nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
(cd build-gpu && timeout 60 ./tests/gpu/cuda_bvh_build_test > $OUT/build-test.log 2>&1; echo "cuda_bvh_build_test exit $?"; grep -E "PASSED|FAILED|Failure" $OUT/build-test.log | head -5)
(cd build-gpu && timeout 150 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-all.log 2>&1; echo "all GPUs ($NG): exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*" $OUT/ctest-gpu-all.log | head -8)
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s53-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
run base near1M,uni1M,near16M,uni16M A=1
for L in 1 2 3 6 8; do run leaf$L near1M,uni1M,near16M SDF_GPU_BVH_MAX_LEAF=$L; done
for R in 8 32; do run radius$R near1M,uni1M SDF_GPU_PLOC_RADIUS=$R; done
run base2 near1M,uni1M A=1
