# Session 51, run 1: warp reductions as redux.sync, resident warps taking batches from a
# counter (SDF_WARP_QUEUE=off: one batch a warp); kernel times, same bytes; ncu of the search.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s51}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -2 $O/summary.txt; cp $O/summary.txt $OUT/build-summary.txt; cp $O/configure.log $OUT/ 2>/dev/null
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s51-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
ALL=near1M,uni1M,near16M,uni16M,cc256
run queue $ALL A=1
run noqueue $ALL SDF_WARP_QUEUE=off
run queue-K1 near1M,uni1M SDF_LIST_RUN=1
run queue-K4 near1M,uni1M,near16M SDF_LIST_RUN=4
run queue-K2 near16M SDF_LIST_RUN=2
run queue $ALL A=1
cat > $O/one.py <<'PY'
import sys, numpy as np, sdf_lattices as sl
sdf = sl.SDF(sl.load_mesh(sys.argv[1]), backend="cuda"); p = np.load(sys.argv[2])
for _ in range(2): sdf.query(p)
PY
NCU=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
for q in on off; do
CUDA_VISIBLE_DEVICES=0 SDF_WARP_QUEUE=$q timeout 100 "$NCU" --clock-control none --metrics gpu__time_duration.sum,launch__registers_per_thread,sm__warps_active.avg.pct_of_peak_sustained_active,launch__occupancy_limit_registers,sm__maximum_warps_per_active_cycle_pct --csv python3 $O/one.py $M $O/near1M.npy > $OUT/ncu-$q.csv 2> $O/ncu.log
echo "ncu $q exit $?"; grep -E "nearest_triangle|finalize|rerank|store|morton|Sort" $OUT/ncu-$q.csv | tail -24 | awk -F'","' '{print substr($5,1,50), $(NF-2), $NF}'
done
CUDA_VISIBLE_DEVICES=0 timeout 120 "$NCU" --clock-control none --kernel-name regex:nearest_triangle_bvh_warp --launch-skip 1 --launch-count 1 --section WarpStateStats --section SchedulerStats --section Occupancy --section LaunchStats --section MemoryWorkloadAnalysis python3 $O/one.py $M $O/near1M.npy > $OUT/ncu-search-sections.txt 2>&1
echo "ncu sections exit $?"; grep -E "Stall|Warp Cycles|Issued Warp|Achieved|Theoretical|Registers|Eligible|No Eligible|Active Warps|Hit Rate|Duration" $OUT/ncu-search-sections.txt | head -40
