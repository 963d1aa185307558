# Session 52, run 1: PLOC's tail in shared memory, one scan, merge+compact fused (2a517d2+):
# GPU tests on two GPUs, build benchmark by tail size, query variants (same bytes as s51),
# ncu of the build's and a 1M near-surface query's kernels.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s52}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt; cp $O/configure.log $OUT/ 2>/dev/null
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
NG=$(nvidia-smi -L | wc -l); nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | head -1
(cd build-gpu && timeout 60 ./tests/gpu/cuda_bvh_build_test > $OUT/build-test.log 2>&1; echo "cuda_bvh_build_test exit $?"; grep -E "PASSED|FAILED|Failure" $OUT/build-test.log | head -5)
(cd build-gpu && timeout 200 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-all.log 2>&1; echo "all GPUs ($NG): exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*" $OUT/ctest-gpu-all.log | head -8)
CUDA_VISIBLE_DEVICES=0 timeout 90 build-gpu/tests/benchmarks/bench_bvh --benchmark_filter='BM_CudaBvhBuild/dragon' --benchmark_min_time=0.3s > $OUT/bench-build.log 2>&1; echo "bench exit $?"; grep -E "BM_" $OUT/bench-build.log | cut -c1-140
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s51-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
run s52 near1M,uni1M,near16M,uni16M A=1
run slots64 near1M SDF_NEAR_LIST_SLOTS=64
cat > $O/one.py <<'PY'
import sys, numpy as np, sdf_lattices as sl
sdf = sl.SDF(sl.load_mesh(sys.argv[1]), backend="cuda"); p = np.load(sys.argv[2])
for _ in range(2): sdf.query(p)
PY
NCU=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
CUDA_VISIBLE_DEVICES=0 timeout 100 "$NCU" --clock-control none --metrics gpu__time_duration.sum,sm__cycles_active.max,sm__cycles_active.avg,launch__registers_per_thread --csv python3 $O/one.py $M $O/near1M.npy > $OUT/ncu-near1M.csv 2> $O/ncu.log
echo "ncu exit $?"
python3 - $OUT/ncu-near1M.csv <<'PY' | tee $OUT/ncu-near1M-kernels.txt
import csv, sys, collections
rows = list(csv.reader(l for l in open(sys.argv[1]) if l.startswith('"')))
h = rows[0]; ki, mi, vi, ii = h.index("Kernel Name"), h.index("Metric Name"), h.index("Metric Value"), h.index("ID")
by = collections.OrderedDict()
for r in rows[1:]:
    by.setdefault((r[ii], r[ki]), {})[r[mi]] = r[vi]
for (i, k), m in by.items():
    print("%5s %10s ns  act max %10s avg %10s  regs %3s  %s" % (i, m.get("gpu__time_duration.sum"), m.get("sm__cycles_active.max"), m.get("sm__cycles_active.avg"), m.get("launch__registers_per_thread"), k[:90]))
PY
CUDA_VISIBLE_DEVICES=0 timeout 100 "$NCU" --clock-control none --kernel-name regex:rerank_near_lists --launch-skip 1 --launch-count 1 --section WarpStateStats --section SchedulerStats --section Occupancy --section LaunchStats --section MemoryWorkloadAnalysis python3 $O/one.py $M $O/near1M.npy > $OUT/ncu-rerank-sections.txt 2>&1
echo "ncu rerank exit $?"; grep -E "Stall|Warp Cycles|Issued Warp|Achieved|Theoretical|Registers|Eligible|Active Warps|Hit Rate|Duration|Throughput" $OUT/ncu-rerank-sections.txt | head -30
