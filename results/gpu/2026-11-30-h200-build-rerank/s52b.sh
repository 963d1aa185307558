# Session 52, run 2: flags kernel back, 32-bit point sort, ranks by sort, re-rank stores
# decided samples (beddb8b): GPU tests (2 GPUs), query variants (same bytes as s51), rank
# scatter vs sort, build bench, ncu kernels (1M, 16.8M near), ncu source of PLOC's tail.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s52b}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
NG=$(nvidia-smi -L | wc -l)
(cd build-gpu && timeout 200 ctest -L gpu --output-on-failure > $OUT/ctest-gpu-all.log 2>&1; echo "all GPUs ($NG): exit $?"; grep -E "tests passed|Skipped|\(Failed\)|\*\*\*" $OUT/ctest-gpu-all.log | head -8)
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s51-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
run s52b near1M,uni1M,near16M,uni16M A=1
run scatter near1M,near16M SDF_RANK_BY=scatter
run sort near1M,near16M SDF_RANK_BY=sort
CUDA_VISIBLE_DEVICES=0 timeout 60 build-gpu/tests/benchmarks/bench_bvh --benchmark_filter='BM_CudaBvhBuild/dragon/device:1' --benchmark_min_time=0.3s > $OUT/bench-build.log 2>&1; echo "bench exit $?"; grep -E "BM_" $OUT/bench-build.log | cut -c1-110
cat > $O/one.py <<'PY'
import sys, numpy as np, sdf_lattices as sl
sdf = sl.SDF(sl.load_mesh(sys.argv[1]), backend="cuda")
for f in sys.argv[2:]:
    p = np.load(f)
    for _ in range(2): sdf.query(p)
PY
NCU=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
CUDA_VISIBLE_DEVICES=0 timeout 120 "$NCU" --clock-control none --metrics gpu__time_duration.sum,sm__cycles_active.max,launch__registers_per_thread --csv python3 $O/one.py $M $O/near1M.npy $O/near16M.npy > $OUT/ncu-near.csv 2> $O/ncu.log
echo "ncu exit $?"
python3 - $OUT/ncu-near.csv <<'PY' > $OUT/ncu-near-kernels.txt
import csv, sys, collections
rows = list(csv.reader(l for l in open(sys.argv[1]) if l.startswith('"')))
h = rows[0]; ki, mi, vi, ii = h.index("Kernel Name"), h.index("Metric Name"), h.index("Metric Value"), h.index("ID")
by = collections.OrderedDict()
for r in rows[1:]:
    by.setdefault((r[ii], r[ki]), {})[r[mi]] = r[vi]
for (i, k), m in by.items():
    print("%5s %12s ns  act max %12s  regs %3s  %s" % (i, m.get("gpu__time_duration.sum"), m.get("sm__cycles_active.max"), m.get("launch__registers_per_thread"), k[:90]))
PY
grep -vE "ploc_nearest|Scan|ploc_flags|merge_compact" $OUT/ncu-near-kernels.txt | tail -40 | cut -c1-140
CUDA_VISIBLE_DEVICES=0 timeout 100 "$NCU" --clock-control none --kernel-name regex:ploc_tail_kernel --launch-count 1 --section WarpStateStats --section SourceCounters --section SchedulerStats --import-source yes -o $O/tail python3 $O/one.py $M > $O/ncu-tail.log 2>&1
echo "ncu tail exit $?"; "$NCU" --import $O/tail.ncu-rep --print-details all > $OUT/ncu-tail-sections.txt 2>&1; grep -E "Stall|Warp Cycles|Issued|Eligible|Duration|Branch" $OUT/ncu-tail-sections.txt | head -20
"$NCU" --import $O/tail.ncu-rep --page source --csv --print-source cuda > $OUT/ncu-tail-source.csv 2>&1; echo "source page exit $?"; head -c 600 $OUT/ncu-tail-source.csv
