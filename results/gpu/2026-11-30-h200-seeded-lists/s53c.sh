# Session 53, run 3: each lane's search seeded by its own descent, batches whose points lie
# apart walked one thread a lane (BatchWalk); variants by knob (same bytes as run 1), and the
# per-batch log (temporary instrumentation, not committed) with and without.
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt; cp $O/configure.log $OUT/
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O > /dev/null 2>&1
run() { label=$1; sets=$2; shift 2; env CUDA_VISIBLE_DEVICES=0 "$@" timeout 120 python3 data/s53-variants.py $M $O $label $sets 2>&1 | grep -v "Warning\|^  \|tree" | tee -a $OUT/variants.log; }
run apart4 near1M,uni1M,near16M,uni16M A=1
run seedoff near1M,uni1M,near16M,uni16M SDF_LIST_SEED=off
run apart0 near1M,uni1M,near16M SDF_LIST_APART=0
run apart2 near1M,uni1M,near16M SDF_LIST_APART=2
run apart8 near1M,uni1M,near16M SDF_LIST_APART=8
run apart4b near1M,uni1M A=1
cat > $O/log.py <<'PY'
import sys, numpy as np, sdf_lattices as sl
sdf = sl.SDF(sl.load_mesh(sys.argv[1]), backend="cuda")
for f in sys.argv[2:]:
    p = np.load(f)
    for _ in range(2): r = sdf.query(p)
PY
for v in apart4:A=1 seedoff:SDF_LIST_SEED=off apart0:SDF_LIST_APART=0; do
  l=${v%%:*}; e=${v#*:}
  env CUDA_VISIBLE_DEVICES=0 $e SDF_BATCH_LOG=$OUT/$l timeout 100 python3 $O/log.py $M $O/near1M.npy $O/uni1M.npy 2>&1 | grep -v Warn
done
python3 data/s53-batchlog2.py $OUT/apart4.1.bin $OUT/apart4.3.bin $OUT/seedoff.1.bin $OUT/seedoff.3.bin $OUT/apart0.1.bin $OUT/apart0.3.bin | tee $OUT/batchlog.txt
rm -f $OUT/*.bin
