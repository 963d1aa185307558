# Session 53, run 2: per-batch log of the listed warp search (temporary instrumentation, not
# committed): batch durations, SM end times, node and triangle counts; near/uniform 1M.
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
O=/tmp/devwork; mkdir -p $O
OUT=$O scripts/device/gpu-check.sh build > /dev/null 2>&1; tail -1 $O/summary.txt
grep -E "error|FAILED" $O/build.log | head -20
export LD_LIBRARY_PATH=$PWD/.gpu-prefix/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes
M=$PWD/data/meshes/dragon-legacy.obj
export PYTHONPATH=$PWD/build-gpu/python
CUDA_VISIBLE_DEVICES=0 python3 data/s49-points.py $M $O > /dev/null 2>&1
cat > $O/log.py <<'PY'
import sys, numpy as np, sdf_lattices as sl
sdf = sl.SDF(sl.load_mesh(sys.argv[1]), backend="cuda")
for f in sys.argv[2:]:
    p = np.load(f)
    for _ in range(2): r = sdf.query(p)
    print(f, "kernel %.3f ms" % (1e3 * r.timings_seconds["kernel"]))
PY
for v in base:A=1 radius8:SDF_GPU_PLOC_RADIUS=8; do
  l=${v%%:*}; e=${v#*:}
  env CUDA_VISIBLE_DEVICES=0 $e SDF_BATCH_LOG=$OUT/$l timeout 100 python3 $O/log.py $M $O/near1M.npy $O/uni1M.npy $O/near16M.npy 2>&1 | grep -v Warn
done
python3 data/s53-batchlog.py $OUT/base.1.bin $OUT/base.3.bin $OUT/base.5.bin $OUT/radius8.1.bin $OUT/radius8.3.bin | tee $OUT/batchlog.txt
rm -f $OUT/*.0.bin $OUT/*.2.bin $OUT/*.4.bin $OUT/*.5.bin
