# Session 50, run 4: the listed search and the re-rank at other register caps (run-time
# selected instantiations); GPU tests under two of them.
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt; cp $O/summary.txt $OUT/build-summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O 2>/dev/null
run() { label=$1; shift; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 60 python3 data/s50-variants.py $M $O $label 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
run listed4 A=1
run listed5 SDF_LISTED_MIN_BLOCKS=5
run listed6 SDF_LISTED_MIN_BLOCKS=6
run rerank6 SDF_RERANK_MIN_BLOCKS=1
run l5r6 SDF_LISTED_MIN_BLOCKS=5 SDF_RERANK_MIN_BLOCKS=1
run listed4 A=1
for b in 5 6; do
  (cd build-gpu && SDF_LISTED_MIN_BLOCKS=$b SDF_RERANK_MIN_BLOCKS=1 timeout 110 ctest -L gpu > $OUT/ctest-listed$b-rerank6.log 2>&1; echo "ctest listed $b rerank capped: exit $?"; grep -E "tests passed|\(Failed\)" $OUT/ctest-listed$b-rerank6.log | head -4)
done
