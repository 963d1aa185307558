# Session 52, run 5: register caps of the one-point-a-lane listed search and of the re-rank
# (same machine, interleaved with the default), the Python module's tests on the GPU.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s52e}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt; cp $O/configure.log $OUT/
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s51-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
run default near1M,uni1M,near16M A=1
run list7 near1M,uni1M SDF_LIST_MIN_BLOCKS=7
run list8 near1M,uni1M SDF_LIST_MIN_BLOCKS=8
run rerank6 near1M,uni1M,near16M SDF_RERANK_MIN_BLOCKS=6
run rerank8 near1M,uni1M,near16M SDF_RERANK_MIN_BLOCKS=8
run default near1M,uni1M,near16M A=1
OUT=$OUT timeout 100 scripts/device/gpu-check.sh python 2>&1 | tail -3
