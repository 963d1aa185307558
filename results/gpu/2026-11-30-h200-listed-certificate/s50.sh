# Session 50, run 1: the listed certificate (candidates to memory, re-rank and nearest_side
# after the walk) against the streamed one; GPU tests on two GPUs and one; peers GPU rows.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s50}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -2 $O/summary.txt; cp $O/summary.txt $OUT/build-summary.txt
grep -E "error|FAILED" $O/build.log | head -20; test -f build-gpu/python/sdf_lattices/_core*.so || ls build-gpu/python/sdf_lattices/ | head -3
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
NG=$(nvidia-smi -L | wc -l); nvidia-smi -L; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O
run() { label=$1; shift; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s50-variants.py $M $O $label 2>&1 | tee -a $OUT/variants.log; }
run listed A=1
run streamed SDF_LIST_CERTIFY=streamed
run listed-walk SDF_WINDING_WALK_ONLY=1
run listed A=1
(cd build-gpu && timeout 200 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-all.log 2>&1; echo "all GPUs ($NG): exit $?"; grep -E "tests passed|Skipped|\(Failed\)" $OUT/ctest-gpu-all.log | head -8)
(cd build-gpu && CUDA_VISIBLE_DEVICES=0 timeout 200 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-one.log 2>&1; echo "one GPU: exit $?"; grep -E "tests passed|Skipped|\(Failed\)" $OUT/ctest-gpu-one.log | head -8)
cat > $O/one.py <<'PY'
import sys, numpy as np, sdf_lattices as sl
sdf = sl.SDF(sl.load_mesh(sys.argv[1]), backend="cuda"); p = np.load(sys.argv[2])
for _ in range(2): sdf.query(p)
PY
NCU=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
CUDA_VISIBLE_DEVICES=0 timeout 100 "$NCU" --clock-control none --metrics gpu__time_duration.sum,launch__registers_per_thread,sm__warps_active.avg.pct_of_peak_sustained_active --csv python3 $O/one.py $M $O/near1M.npy > $OUT/ncu-listed.csv 2> $O/ncu.log
echo "ncu exit $?"; grep -E "nearest_triangle|finalize|rerank|store" $OUT/ncu-listed.csv | tail -15 | awk -F'","' '{print substr($5,1,60), $(NF-2), $NF}'
CUDA_VISIBLE_DEVICES=0 timeout 200 build-gpu/bin/run-experiment data/s49-peers-gpu.json --output-root $O/peers --no-cache > $OUT/peers-gpu.log 2>&1; echo "peers exit $?"
grep -E "=>|bvh_gpu|cubql" $OUT/peers-gpu.log | cut -c1-170 | tail -30
