# The device scripts' common start, sourced: strict mode, the repository root as the working
# folder, $OUT made (default gpu-out), $B the GPU build folder, log() into $OUT/summary.txt.
set -uo pipefail
cd "$(dirname "$0")/../.."
OUT=${OUT:-$PWD/gpu-out}
mkdir -p "$OUT"
B=build-gpu
log() { echo "== $(date +%T) $*" | tee -a "$OUT/summary.txt"; }
