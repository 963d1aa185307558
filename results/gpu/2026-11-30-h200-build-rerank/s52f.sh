# Session 52, run 6: the new defaults (listed search 8 blocks, re-rank 6) against the old
# (SDF_LIST_MIN_BLOCKS=6 SDF_RERANK_MIN_BLOCKS=1) on one machine; sort bits 24 and 27.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s52f}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O 2>/dev/null
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s51-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
S=near1M,uni1M,near16M,uni16M
run default $S A=1
run old $S SDF_LIST_MIN_BLOCKS=6 SDF_RERANK_MIN_BLOCKS=1
run bits24 $S SDF_SORT_BITS=24
run bits27 near1M,near16M SDF_SORT_BITS=27
run default $S A=1
