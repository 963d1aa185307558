# Session 51, run 2: lists that drop their largest entry (overflow only within the final
# radius); points per thread under the batch queue; where the search kernel's issue slots go.
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s51b}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s51-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
ALL=near1M,uni1M,near16M,uni16M
run default $ALL A=1
run K1 $ALL SDF_LIST_RUN=1
run K2 $ALL SDF_LIST_RUN=2
run K4 near16M,uni16M SDF_LIST_RUN=4
cat > $O/one.py <<'PY'
import sys, numpy as np, sdf_lattices as sl
sdf = sl.SDF(sl.load_mesh(sys.argv[1]), backend="cuda"); p = np.load(sys.argv[2])
for _ in range(2): sdf.query(p)
PY
NCU=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
CUDA_VISIBLE_DEVICES=0 SDF_LIST_RUN=1 timeout 100 "$NCU" --clock-control none --metrics gpu__time_duration.sum,launch__registers_per_thread,sm__warps_active.avg.pct_of_peak_sustained_active --csv python3 $O/one.py $M $O/near1M.npy > $OUT/ncu-k1.csv 2> $O/ncu.log
echo "ncu exit $?"; grep -E "nearest_triangle|finalize|rerank|store|morton|Sort|gather" $OUT/ncu-k1.csv | tail -30 | awk -F'","' '{print substr($5,1,50), $(NF-2), $NF}' | grep -v "^void radix_sort.*registers"
CUDA_VISIBLE_DEVICES=0 SDF_LIST_RUN=1 timeout 150 "$NCU" --clock-control none --kernel-name regex:nearest_triangle_bvh_warp --launch-skip 1 --launch-count 1 --section SourceCounters --section InstructionStats --section WarpStateStats --section ComputeWorkloadAnalysis --print-source sass --print-details all -o $O/search -f python3 $O/one.py $M $O/near1M.npy > $OUT/ncu-search.txt 2>&1
echo "ncu source exit $?"
"$NCU" -i $O/search.ncu-rep --page source --csv --print-source sass > $O/search-sass.csv 2>/dev/null; echo "sass rows $(wc -l < $O/search-sass.csv)"
gzip -c $O/search-sass.csv > $OUT/search-sass.csv.gz
"$NCU" -i $O/search.ncu-rep --page details --print-details all > $OUT/ncu-search-details.txt 2>&1
grep -E "Stall|Issued|Executed Ipc|Pipe|Warp Cycles|Branch|Divergent" $OUT/ncu-search-details.txt | head -40
