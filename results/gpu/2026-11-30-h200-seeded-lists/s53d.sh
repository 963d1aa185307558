# Session 53, run 4 (b4cd820, the seeded point lists): GPU tests on two GPUs and on one, the
# query variants (seeded vs SDF_LIST_SEED=off, same bytes as run 1), the peers' GPU rows, the
# Python module's tests on the GPU, a memcheck of the point queries.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-b4cd820}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt; cp $O/configure.log $OUT/
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
NG=$(nvidia-smi -L | wc -l); nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
(cd build-gpu && timeout 150 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-all.log 2>&1; echo "all GPUs ($NG): exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*" $OUT/ctest-gpu-all.log | head -8)
(cd build-gpu && CUDA_VISIBLE_DEVICES=0 timeout 150 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-one.log 2>&1; echo "one GPU: exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*" $OUT/ctest-gpu-one.log | head -8)
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O > /dev/null 2>&1
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s53-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  \|tree" | tee -a $OUT/variants.log; }
run seeded near1M,uni1M,near16M,uni16M A=1
run unseeded near1M,uni1M,near16M,uni16M SDF_LIST_SEED=off
CUDA_VISIBLE_DEVICES=0 timeout 200 build-gpu/bin/run-experiment data/s49-peers-gpu.json --output-root $O/peers --no-cache > $OUT/peers-gpu.log 2>&1; echo "peers exit $?"
grep -E "=>" $OUT/peers-gpu.log | cut -c1-150
R=$(ls -d $O/peers/*/*/ | head -1); echo $R; cp $R/manifest.json $OUT/peers-manifest.json; cp $R/metrics.json $OUT/peers-metrics.json
OUT=$OUT timeout 90 scripts/device/gpu-check.sh python 2>&1 | tail -2
timeout 60 compute-sanitizer --tool memcheck --error-exitcode 3 build-gpu/tests/gpu/cuda_bvh_test --gtest_filter=*PointQueries* > $OUT/sanitizer-memcheck.txt 2>&1; echo "memcheck exit $? $(grep 'ERROR SUMMARY' $OUT/sanitizer-memcheck.txt)"
