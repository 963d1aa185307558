#!/usr/bin/env bash
# Distributed runs on the GPU machine (docs/distributed.md, issue 15): builds with CUDA and MPI
# (warnings as errors), runs the MPI tests there, then samples a study on the GPU with one
# process and with 2 ranks sharing the GPU and compares every field file byte for byte, with
# the timings of both; step python: the Python module's collective sample() on 2 ranks sharing
# the GPU against one process, bit for bit (when the module is built there). Used with the
# device tool:
#   carry: .gpu-prefix (as scripts/device/gpu-check.sh)      steps: build test gpu python
#   scripts/device/gpu-mpi.sh build test gpu python
# Output under $OUT: summary.txt, the logs, the manifests of the GPU runs.
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-$PWD/gpu-out}
mkdir -p "$OUT"
PREFIX=$PWD/.gpu-prefix/root/usr
export LD_LIBRARY_PATH=$PREFIX/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export SDF_DATA_PATH=$PWD/data/meshes
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# One machine: shared memory only (no network probing); no CMA single copy (containers forbid ptrace).
export OMPI_MCA_btl=self,vader OMPI_MCA_btl_vader_single_copy_mechanism=none
B=build-gpu-mpi
log() { echo "== $(date +%T) $*" | tee -a "$OUT/summary.txt"; }
cmake_common=(-G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PREFIX")
[ -f /usr/include/openssl/evp.h ] || cmake_common+=(-DOPENSSL_ROOT_DIR="$PREFIX" -DOPENSSL_INCLUDE_DIR="$PREFIX/include"
    -DOPENSSL_CRYPTO_LIBRARY="$PREFIX/lib/x86_64-linux-gnu/libcrypto.so.3"
    -DCMAKE_CXX_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu" -DCMAKE_CUDA_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu")

# A GPU study: brute force and BVH on a CC and a BCC lattice of a 65,536-triangle torus.
write_config() {
    cat > "$1" <<'JSON'
{
  "name": "mpi_gpu",
  "kind": "sampling",
  "mesh": {"shape": "torus", "major_segments": 256, "minor_segments": 128},
  "lattices": [
    {"type": "cc", "resolution": [192, 192, 192]},
    {"type": "bcc", "resolution": [152, 152, 304]}
  ],
  "sampler": {"backend": "cuda", "progress": false},
  "sweep": {"sampler.method": ["brute_force", "bvh"]}
}
JSON
}

# Per field: seconds of the whole sampling, and per rank (from metrics.json / manifest.json).
timings() {
    python3 - "$1" <<'PY'
import json, sys, glob, os
run = sys.argv[1]
m = json.load(open(os.path.join(run, "metrics.json")))
for p in m.get("points", [{"name": "", "metrics": m}]):
    for f in p["metrics"]["fields"]:
        d = f["sampler"].get("distributed")
        line = f"  {p['name']:28s} {f['name']:22s} {f['seconds']:8.3f} s total, kernel {f['kernel_seconds']:8.3f} s"
        if d:
            ranks = ", ".join(f"rank {s['rank']} planes {s['z_planes']} {s['seconds']:.3f} s" for s in d["slabs"])
            lb = d["load_balance"]
            line += f"; {ranks}; max/mean {lb['seconds_max_over_mean']:.3f} (estimate {lb['estimate_max_over_mean']:.3f})"
        print(line)
man = json.load(open(os.path.join(run, "manifest.json")))
for f in (man.get("distributed") or {}).get("fields", []):
    if "write" in f:  # the field files written by the ranks (MPI-IO)
        ranks = ", ".join(f"rank {s['rank']} {s['write_bytes']} B {s['write_seconds']:.3f} s" for s in f["slabs"])
        print(f"  write {f['lattice']}: {f['write']}, {f['write_bytes']} bytes in {f['write_seconds']:.3f} s; {ranks}")
PY
}

for step in "$@"; do case "$step" in
build)
    log "configure + build (CUDA, MPI, warnings as errors)"
    nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | tee -a "$OUT/summary.txt"
    mpirun --version 2>&1 | head -1 | tee -a "$OUT/summary.txt"
    cmake -S . -B $B "${cmake_common[@]}" -DSDF_ENABLE_CUDA=ON -DSDF_ENABLE_MPI=ON -DCMAKE_CUDA_ARCHITECTURES=90 \
        -DSDF_WARNINGS_AS_ERRORS=ON > "$OUT/configure.log" 2>&1 || { tail -30 "$OUT/configure.log"; exit 1; }
    grep "sdf:" "$OUT/configure.log" | tee -a "$OUT/summary.txt"
    cmake --build $B -j "$(nproc)" --target run-experiment slab_sampling_test -- -k 0 > "$OUT/build.log" 2>&1 ||
        { grep -E "error|warning|FAILED" "$OUT/build.log" | head -40; exit 1; }
    log "built" ;;
test)
    log "MPI tests and slab test (CPU samplers)"
    (cd $B && ctest -R "slab_sampling|mpi_" --output-on-failure > "$OUT/ctest-mpi.log" 2>&1; echo "ctest exit $?") | tee -a "$OUT/summary.txt"
    grep -E "Test +#|tests passed" "$OUT/ctest-mpi.log" | tee -a "$OUT/summary.txt" ;;
gpu)
    log "GPU: one process vs 2 ranks sharing the GPU"
    W=$(mktemp -d)
    write_config "$W/mpi_gpu.json"
    $B/bin/run-experiment "$W/mpi_gpu.json" --no-cache --quiet --output-root "$W/serial" > "$OUT/gpu-serial.log" 2>&1 ||
        { tail -20 "$OUT/gpu-serial.log"; exit 1; }
    mpirun --oversubscribe -np 2 $B/bin/run-experiment "$W/mpi_gpu.json" --no-cache --quiet --output-root "$W/np2" \
        > "$OUT/gpu-np2.log" 2>&1 || { tail -20 "$OUT/gpu-np2.log"; exit 1; }
    serial=$(ls -d "$W"/serial/mpi_gpu/*/) np2=$(ls -d "$W"/np2/mpi_gpu/*/)
    n=0 bad=0
    for f in $(cd "$serial" && find . -name '*.raw' | sort); do
        n=$((n + 1))
        cmp -s "$serial/$f" "$np2/$f" || { bad=$((bad + 1)); echo "DIFFERS: $f" | tee -a "$OUT/summary.txt"; }
    done
    echo "channel files compared: $n, differing: $bad" | tee -a "$OUT/summary.txt"
    (cd "$np2" && find . -name '*.raw' | sort | xargs sha256sum) > "$OUT/gpu-np2.sha256"
    echo "one process:" | tee -a "$OUT/summary.txt"; timings "$serial" | tee -a "$OUT/summary.txt"
    echo "2 ranks, one GPU:" | tee -a "$OUT/summary.txt"; timings "$np2" | tee -a "$OUT/summary.txt"
    cp "$np2/manifest.json" "$OUT/gpu-np2-manifest.json"; cp "$serial/manifest.json" "$OUT/gpu-serial-manifest.json"
    rm -rf "$W"
    [ "$bad" -eq 0 ] && [ "$n" -eq 12 ] || exit 1 ;;
python)
    log "Python: sample() collective on 2 ranks sharing the GPU vs one process"
    if ! grep -q "Python module ON" "$OUT/configure.log" 2>/dev/null; then
        echo "the Python module is not built on this machine (pybind11, python3-dev): skipped" | tee -a "$OUT/summary.txt"
        continue
    fi
    cmake --build $B -j "$(nproc)" --target sdf_lattices -- -k 0 > "$OUT/build-python.log" 2>&1 ||
        { grep -E "error|warning|FAILED" "$OUT/build-python.log" | head -40; exit 1; }
    (cd $B && ctest -R "python_module_mpi" --output-on-failure > "$OUT/ctest-python-mpi.log" 2>&1; echo "ctest exit $?") | tee -a "$OUT/summary.txt"
    grep -E "Test +#|tests passed" "$OUT/ctest-python-mpi.log" | tee -a "$OUT/summary.txt"
    W=$(mktemp -d)
    cat > "$W/collective.py" <<'PY'
import time
import sdf_lattices as sl
rank = sl.distributed()["rank"]
mesh = sl.load_mesh("shape:torus")
def arrays(f):
    out = []
    for a in (f.values, f.gradient, f.triangle):
        out += list(a) if isinstance(a, tuple) else [a]
    return out
bad = 0
for lattice, resolution in [("cc", 128), ("bcc", [100, 100, 200])]:
    for method in ["brute_force", "bvh"]:
        args = dict(lattice=lattice, resolution=resolution, method=method, backend="cuda")
        t = time.perf_counter()
        field = sl.sample(mesh, **args)
        together = time.perf_counter() - t
        if rank != 0:
            continue  # rank 1 waits in the next collective call while rank 0 samples alone
        t = time.perf_counter()
        alone = sl.sample(mesh, distributed=False, **args)
        one = time.perf_counter() - t
        same = all(a.tobytes() == b.tobytes() for a, b in zip(arrays(field), arrays(alone)))
        bad += not same
        d = field.sampler["distributed"]
        slabs = ", ".join(f"rank {s['rank']} device {s.get('device')} {s['seconds']:.3f} s" for s in d["slabs"])
        print(f"{field.notation} {method}: {'identical' if same else 'DIFFERS'}; 2 ranks {together:.3f} s "
              f"(sampling {field.seconds:.3f} s; {slabs}), one process {one:.3f} s", flush=True)
if rank == 0:
    print("collective fields differing from one process's:", bad, flush=True)
PY
    python=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' $B/CMakeCache.txt)  # the module's interpreter
    PYTHONPATH=$B/python mpirun --oversubscribe -np 2 "${python:-python3}" "$W/collective.py" > "$OUT/gpu-python.log" 2>&1
    status=$?
    tee -a "$OUT/summary.txt" < "$OUT/gpu-python.log"
    rm -rf "$W"
    [ "$status" -eq 0 ] && grep -q "differing from one process's: 0" "$OUT/gpu-python.log" || exit 1 ;;
*) echo "unknown step $step"; exit 2 ;;
esac; done
log done
