# Session 51, run 5: kernel times of one query of 16.8M near-surface points and of the device
# tree's build (ncu), the committed tree (a172f81, prefetch removed).
export SDF_SOURCE_COMMIT=${SDF_SOURCE_COMMIT:-s51e}
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes SDF_PEERS_DIR=$PWD/data/peers
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O 2>/dev/null
CUDA_VISIBLE_DEVICES=0 timeout 120 python3 data/s51-variants.py $M $O default near1M,uni1M,near16M,uni16M 2>&1 | grep -v "Warning\|^  " | tee -a $OUT/variants.log
cat > $O/one.py <<'PY'
import sys, numpy as np, sdf_lattices as sl
sdf = sl.SDF(sl.load_mesh(sys.argv[1]), backend="cuda"); p = np.load(sys.argv[2])
sdf.query(p)
PY
NCU=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
CUDA_VISIBLE_DEVICES=0 timeout 200 "$NCU" --clock-control none --metrics gpu__time_duration.sum --csv python3 $O/one.py $M $O/near16M.npy > $OUT/ncu-16m.csv 2> $O/ncu.log
echo "ncu exit $?"
python3 - $OUT/ncu-16m.csv <<'PY'
import csv, sys, collections
rows = [r for r in csv.reader(open(sys.argv[1])) if len(r) > 10]
h = rows[0]; k = h.index("Kernel Name"); v = h.index("Metric Value"); ids = h.index("ID")
agg = collections.OrderedDict()
for r in rows[1:]:
    name = r[k][:70]; agg.setdefault(name, []).append(float(r[v].replace(",", "")))
for name, t in agg.items(): print("%9.1f us  x%-4d %s" % (sum(t) / 1e3, len(t), name))
PY
