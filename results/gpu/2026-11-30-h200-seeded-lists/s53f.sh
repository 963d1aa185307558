# Session 53, run 6: a point list's batches taken costliest first (seed_list_batches, a sort of
# their costs) against Morton order with in-walk seeds (SDF_LIST_ORDER=morton, b4cd820's);
# GPU tests on two GPUs and one; the peers' GPU rows.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s53f}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O > /dev/null 2>&1
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 100 python3 data/s53-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  \|tree" | tee -a $OUT/variants.log; }
run cost near1M,uni1M,near16M,uni16M A=1
run morton near1M,uni1M,near16M,uni16M SDF_LIST_ORDER=morton
run cost2 near1M,uni1M A=1
(cd build-gpu && timeout 150 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-all.log 2>&1; echo "two GPUs: exit $?"; grep -E "tests passed|\(Failed\)|\*\*\*" $OUT/ctest-gpu-all.log | head -8)
(cd build-gpu && CUDA_VISIBLE_DEVICES=0 timeout 150 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-one.log 2>&1; echo "one GPU: exit $?"; grep -E "tests passed|\(Failed\)|\*\*\*" $OUT/ctest-gpu-one.log | head -8)
CUDA_VISIBLE_DEVICES=0 timeout 150 build-gpu/bin/run-experiment data/s49-peers-gpu.json --output-root $O/peers --no-cache > $OUT/peers-gpu.log 2>&1; echo "peers exit $?"
grep -E "=>" $OUT/peers-gpu.log | cut -c1-150
R=$(ls -d $O/peers/*/*/ | head -1); cp $R/manifest.json $OUT/peers-manifest.json; cp $R/metrics.json $OUT/peers-metrics.json
