# Session 51, run 4: 16 list entries by default; the walk prefetching its children into L1
# (SDF_WARP_PREFETCH=off: not); the peers' GPU rows with every default.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s51d}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O 2>/dev/null
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s51-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
ALL=near1M,uni1M,near16M,uni16M
run prefetch $ALL A=1
run noprefetch $ALL SDF_WARP_PREFETCH=off
run prefetch $ALL A=1
CUDA_VISIBLE_DEVICES=0 timeout 300 build-gpu/bin/run-experiment data/s49-peers-gpu.json --output-root $O/peers --no-cache > $OUT/peers-gpu.log 2>&1; echo "peers exit $?"
grep -E "=>|bvh_gpu|cubql" $OUT/peers-gpu.log | cut -c1-170 | tail -30
R=$(ls -d $O/peers/*/ | head -1); cp $R/manifest.json $OUT/peers-manifest.json; cp $R/metrics.json $OUT/peers-metrics.json; ls $R
