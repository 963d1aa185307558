# Session 52, run 4 (919a6f2): the peers' GPU rows, GPU tests on one GPU, the Python module's tests on the GPU.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-919a6f2}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader | head -2
CUDA_VISIBLE_DEVICES=0 timeout 330 build-gpu/bin/run-experiment data/s49-peers-gpu.json --output-root $O/peers --no-cache > $OUT/peers-gpu.log 2>&1; echo "peers exit $?"
grep -E "=>|bvh_gpu|cubql" $OUT/peers-gpu.log | cut -c1-150 | tail -30
R=$(ls -d $O/peers/*/*/ | head -1); echo $R; cp $R/manifest.json $OUT/peers-manifest.json; cp $R/metrics.json $OUT/peers-metrics.json
(cd build-gpu && CUDA_VISIBLE_DEVICES=0 timeout 150 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-one.log 2>&1; echo "one GPU: exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*" $OUT/ctest-gpu-one.log | head -8)
OUT=$OUT timeout 100 scripts/device/gpu-check.sh python 2>&1 | tail -3
