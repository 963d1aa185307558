# Session 51, run 3: the points-per-thread rule (1 at 1M, 2 at 16.8M), overflowed lists straight
# to the wide search, list entries 8/12/16; where the search kernel's issue slots go (SASS).
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s51c}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O 2>/dev/null
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s51-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log; }
ALL=near1M,uni1M,near16M,uni16M
run slots8 $ALL A=1
run slots12 $ALL SDF_NEAR_LIST_SLOTS=12
run slots16 $ALL SDF_NEAR_LIST_SLOTS=16
cat > $O/one.py <<'PY'
import sys, numpy as np, sdf_lattices as sl
sdf = sl.SDF(sl.load_mesh(sys.argv[1]), backend="cuda"); p = np.load(sys.argv[2])
for _ in range(2): sdf.query(p)
PY
NCU=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
for sl in 8 16; do
CUDA_VISIBLE_DEVICES=0 SDF_NEAR_LIST_SLOTS=$sl timeout 100 "$NCU" --clock-control none --metrics gpu__time_duration.sum --csv python3 $O/one.py $M $O/near1M.npy > $OUT/ncu-slots$sl.csv 2> $O/ncu.log
echo "ncu slots $sl exit $?"; grep -E "nearest_triangle|finalize|rerank|store" $OUT/ncu-slots$sl.csv | tail -4 | awk -F'","' '{print substr($5,1,50), $(NF-2), $NF}'
done
CUDA_VISIBLE_DEVICES=0 timeout 150 "$NCU" --clock-control none --kernel-name regex:nearest_triangle_bvh_warp --launch-skip 1 --launch-count 1 --section SourceCounters --section InstructionStats --section WarpStateStats --section ComputeWorkloadAnalysis -o $O/search -f python3 $O/one.py $M $O/near1M.npy > $OUT/ncu-search.txt 2>&1
echo "ncu source exit $?"; tail -3 $OUT/ncu-search.txt
"$NCU" -i $O/search.ncu-rep --page source --csv --print-source sass > $O/search-sass.csv 2>$O/sass.err; echo "sass rows $(wc -l < $O/search-sass.csv)"; head -3 $O/sass.err
gzip -c $O/search-sass.csv > $OUT/search-sass.csv.gz
"$NCU" -i $O/search.ncu-rep --page details --print-details all > $OUT/ncu-search-details.txt 2>&1
grep -E "Stall|Issued|Executed Ipc|Pipe|Warp Cycles|Branch|Divergent" $OUT/ncu-search-details.txt | head -30
