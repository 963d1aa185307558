#!/usr/bin/env bash
# The portable wheel on a lent GPU machine (stock Ubuntu + CUDA + PyTorch, no network, no Debian
# dev packages; docs/python.md, "The portable wheel"):
#   scripts/device/wheel-check.sh WHEEL     installs WHEEL (a .whl built elsewhere for this
#                                           machine's Python) and tests it
#   scripts/device/wheel-check.sh build     builds the portable wheel here from this checkout
#                                           (-DSDF_WHEEL=ON, CUDA for every architecture of
#                                           the default list; WHEEL_CUDA_ARCHS overrides it),
#                                           copies it to $OUT, then installs and tests it
#   carry: .gpu-prefix data   (scripts/device/make-gpu-prefix: the Debian headers and static
#                              libraries the build needs; only for "build")
# Testing: a fresh virtual environment with --system-site-packages (PyTorch, NumPy, pytest
# from the machine), `pip install --no-deps WHEEL`, `import sdf_lattices`, build_info(),
# every ELF file's NEEDED list and the wheel's size (python/wheel_libs.py), then
# tests/python_module against the installed package and tools, with LD_LIBRARY_PATH cleared
# (the wheel must not lean on .gpu-prefix). Output under $OUT: summary.txt and the logs.
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-$PWD/wheel-out}
mkdir -p "$OUT"
log() { echo "== $(date +%T) $*" | tee -a "$OUT/summary.txt"; }
[ $# -eq 1 ] || { sed -n '2,17p' "$0"; exit 2; }
PY=${PYTHON:-python3}

if [ "$1" = build ]; then
    PREFIX=$PWD/.gpu-prefix/root/usr
    scripts/device/unpack-debs  # the .deb files of make-gpu-prefix, once
    B=build-wheel
    options=(-G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PREFIX" -DSDF_SOURCE_COMMIT="${SDF_SOURCE_COMMIT:-}"
             -DSDF_WHEEL=ON -DSDF_BUILD_PEERS=OFF -DSDF_BUILD_TESTS=OFF -DSDF_BUILD_BENCHMARKS=OFF
             -DSDF_BUILD_PYTHON=ON -DSDF_ENABLE_CUDA=ON -DPython3_EXECUTABLE="$(command -v "$PY")")
    [ -n "${WHEEL_CUDA_ARCHS:-}" ] && options+=(-DCMAKE_CUDA_ARCHITECTURES="$WHEEL_CUDA_ARCHS")
    "$PY" -m pybind11 --cmakedir > /dev/null 2>&1 && options+=(-Dpybind11_DIR="$("$PY" -m pybind11 --cmakedir)")
    # OpenSSL: the machine's libcrypto.a where it has libssl-dev, else .gpu-prefix's (its
    # libcrypto.a if make-gpu-prefix kept it, else libcrypto.so.3, which setup.py then bundles).
    if [ ! -f /usr/include/openssl/evp.h ]; then
        crypto=$PREFIX/lib/x86_64-linux-gnu/libcrypto.a
        [ -f "$crypto" ] || crypto=$PREFIX/lib/x86_64-linux-gnu/libcrypto.so.3
        options+=(-DOPENSSL_ROOT_DIR="$PREFIX" -DOPENSSL_INCLUDE_DIR="$PREFIX/include" -DOPENSSL_CRYPTO_LIBRARY="$crypto"
                  -DCMAKE_CXX_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu" -DCMAKE_CUDA_FLAGS="-isystem $PREFIX/include/x86_64-linux-gnu")
    fi
    export PATH=$PATH:/usr/local/cuda/bin
    log "configure the portable wheel's build ($B)"
    cmake -S . -B $B "${options[@]}" > "$OUT/configure.log" 2>&1 || { tail -30 "$OUT/configure.log"; exit 1; }
    grep "sdf:" "$OUT/configure.log" | tee -a "$OUT/summary.txt"
    log "build sdf_package"
    start=$(date +%s)
    # The bundling step (setup.py) finds .gpu-prefix's shared libraries through ldd.
    LD_LIBRARY_PATH=$PREFIX/lib/x86_64-linux-gnu cmake --build $B -j "$(nproc)" --target sdf_package > "$OUT/build.log" 2>&1 ||
        { grep -E "error|FAILED" "$OUT/build.log" | head -40; exit 1; }
    log "built in $(( $(date +%s) - start )) s"
    rm -rf "$OUT/wheel" && mkdir -p "$OUT/wheel"
    log "pip wheel (SDF_CMAKE_BUILD_DIR=$B: packs this tree, bundles and checks the libraries)"
    LD_LIBRARY_PATH=$PREFIX/lib/x86_64-linux-gnu SDF_CMAKE_BUILD_DIR=$PWD/$B PIP_NO_INDEX=1 \
        "$PY" -m pip wheel --no-build-isolation --no-deps -w "$OUT/wheel" . > "$OUT/pip-wheel.log" 2>&1 ||
        { tail -30 "$OUT/pip-wheel.log"; echo "pip wheel failed (setuptools and wheel must be importable by $PY)" | tee -a "$OUT/summary.txt"; exit 1; }
    grep -E "bundled into|^  [a-z]" "$OUT/pip-wheel.log" | tee -a "$OUT/summary.txt"
    wheel=$(ls "$OUT"/wheel/sdf_lattices-*.whl)
else
    wheel=$(realpath "$1")
fi
[ -f "$wheel" ] || { echo "wheel-check: no wheel file $wheel" | tee -a "$OUT/summary.txt"; exit 1; }

# From here on nothing of .gpu-prefix: the wheel alone.
unset LD_LIBRARY_PATH PYTHONPATH
log "$(basename "$wheel"): $(du -h "$wheel" | cut -f1) ($(stat -c %s "$wheel") bytes)"
"$PY" python/wheel_libs.py "$wheel" 2>&1 | tee "$OUT/needed.txt" | tee -a "$OUT/summary.txt"
elf_check=${PIPESTATUS[0]}

V=$(mktemp -d)/venv
log "venv --system-site-packages, pip install --no-deps"
if ! "$PY" -m venv --system-site-packages "$V" > "$OUT/venv.log" 2>&1; then
    # Without ensurepip (Ubuntu's python3-venv missing): a venv without pip, filled by the system pip.
    "$PY" -m venv --system-site-packages --without-pip "$V" >> "$OUT/venv.log" 2>&1 || { cat "$OUT/venv.log"; exit 1; }
    PIP=("$PY" -m pip --python "$V/bin/python")
else
    PIP=("$V/bin/python" -m pip)
fi
# --system-site-packages leaves out the user site (~/.local) and any PYTHONPATH folder, where a
# stock image may keep NumPy and PyTorch: the venv sees every site folder of the stock
# interpreter through a .pth file, so that the test uses exactly the machine's NumPy and PyTorch.
purelib=$("$V/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")
"$PY" -c "import site, sys; print('\n'.join(p for p in sys.path if p.endswith(('site-packages', 'dist-packages'))))" \
    > "$purelib/_stock_python_site.pth"
log "stock interpreter: $("$PY" -c 'import numpy, torch; print("numpy", numpy.__version__, "torch", torch.__version__, "from", numpy.__file__.rsplit("/", 2)[0])' 2>&1 | tail -1)"
PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 "${PIP[@]}" install --no-deps "$wheel" > "$OUT/pip-install.log" 2>&1 ||
    { tail -20 "$OUT/pip-install.log"; exit 1; }
cd "$(dirname "$V")"   # away from the checkout's python/ folder
"$V/bin/python" -c "import json, sdf_lattices as s; print(s.__file__); print(json.dumps(s.build_info(), indent=1))" \
    2>&1 | tee -a "$OUT/summary.txt"
import_check=${PIPESTATUS[0]}
cd - > /dev/null
for tool in sdf-query sdf-eval run-experiment sdf-sample sdf-render; do
    "$V/bin/$tool" --version 2>&1 | head -1 | tee -a "$OUT/summary.txt"
done

log "tests/python_module against the installed wheel"
ROOT=$PWD
(cd "$(dirname "$V")" && SDF_DATA_PATH=$ROOT/data/meshes PATH="$V/bin:$PATH" SDF_QUERY=$V/bin/sdf-query \
    SDF_EVAL=$V/bin/sdf-eval RUN_EXPERIMENT=$V/bin/run-experiment \
    "$V/bin/python" -m pytest -q -rs -p no:cacheprovider "$ROOT/tests/python_module") > "$OUT/pytest.log" 2>&1
pytest_check=$?
grep -E "passed|failed|SKIPPED|error" "$OUT/pytest.log" | tail -30 | tee -a "$OUT/summary.txt"
log "ELF check exit $elf_check, import exit $import_check, pytest exit $pytest_check"
[ "$elf_check" -eq 0 ] && [ "$import_check" -eq 0 ] && [ "$pytest_check" -eq 0 ]
