#!/usr/bin/env bash
# Distributed runs under mpirun (docs/distributed.md), small and fast for CI's 2 cores.
#   mpi_runs.sh bit_identity RUN_EXPERIMENT MPIEXEC
#       a sampling sweep (brute force and BVH, CC and BCC lattices, a procedural torus) run by
#       one process and by 1, 2 and 3 ranks: every field file's bytes must be equal, and the
#       manifest must record the ranks and that every rank wrote its own slab's bytes of every
#       channel file (MPI-IO), and nothing more.
#   mpi_runs.sh gpu RUN_EXPERIMENT MPIEXEC
#       on two GPUs (skipped, 77, below two): mpirun -np 2 and one process with "devices": "all"
#       give one GPU's channel files byte for byte, each rank's slab on another GPU.
#   mpi_runs.sh narrow_band RUN_EXPERIMENT MPIEXEC
#       a narrow band (sampler band_width) sampled by one process and by 3 ranks: the same
#       field files byte for byte and the same counters in the field's sampler report (the
#       band's points in and outside it, the points computed and searched), every rank's
#       merged (SamplerReport::merge), not rank 0's.
#   mpi_runs.sh ci_smoke RUN_EXPERIMENT MPIEXEC
#       the CI smoke reconstruction study (configs/ci_smoke.json) on 2 ranks passes its
#       baseline check: the root's reconstructions and metrics work on distributed fields.
#   mpi_runs.sh mismatch RUN_EXPERIMENT MPIEXEC
#       ranks started with different options (mpirun's "A : B" form) or different configs
#       stop, every one of them, within seconds, with a message naming the option and the
#       ranks; nothing is run or published.
#   mpi_runs.sh failure RUN_EXPERIMENT MPIEXEC
#       a rank that fails (SDF_MPI_FAIL_RANK) or dies (SDF_MPI_FAIL_MODE=kill) must fail the
#       run: non-zero exit, a message naming the rank and its host, no run directory, no
#       cache entry; also when it fails or dies while writing the field files
#       (SDF_MPI_FAIL_STAGE=write; the cache then holds the complete fields, sampled before).
set -euo pipefail
case_name=$1 tool=$2 mpiexec=$3
work=$(mktemp -d "${TMPDIR:-/tmp}/sdf-mpi-test.XXXXXX")
trap 'rm -rf "$work"' EXIT
# CI runs as root; shared memory only (one machine); more ranks than cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl=self,vader OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_rmaps_base_oversubscribe=1
mpi() { local n=$1; shift; "$mpiexec" --oversubscribe -np "$n" "$@"; }
fail() { echo "FAIL: $*" >&2; exit 1; }

cat > "$work/mpi_fields.json" <<'JSON'
{
  "name": "mpi_fields",
  "kind": "sampling",
  "mesh": {"shape": "torus", "major_segments": 24, "minor_segments": 12},
  "lattices": [
    {"type": "cc", "resolution": [11, 9, 13]},
    {"type": "bcc", "resolution": [8, 7, 18]}
  ],
  "sampler": {"backend": "cpu", "progress": false},
  "output": {"dtype": "float64"},
  "sweep": {"sampler.method": ["brute_force", "bvh"]}
}
JSON

run_dir_of() {  # the one run directory under $1/$2
    local dirs=("$1/$2"/*/)
    [ "${#dirs[@]}" -eq 1 ] && [ -d "${dirs[0]}" ] || fail "expected one run directory under $1/$2"
    echo "${dirs[0]%/}"
}
run_dir() { run_dir_of "$1" mpi_fields; }

if [ "$case_name" = bit_identity ]; then
    "$tool" "$work/mpi_fields.json" --no-cache --quiet --output-root "$work/serial" > "$work/serial.log"
    serial=$(run_dir "$work/serial")
    (cd "$serial" && find . -name '*.raw' | sort) > "$work/serial.files"
    [ "$(wc -l < "$work/serial.files")" -eq 12 ] || fail "expected 12 channel files (2 methods x 2 lattices x 3 channels)"
    (cd "$serial" && find . | sort) > "$work/serial.tree"
    same_fields() {  # label, run directory: the same channel files, byte for byte
        (cd "$2" && find . -name '*.raw' | sort) | diff "$work/serial.files" - || fail "$1: other files"
        while read -r f; do
            cmp "$serial/$f" "$2/$f" || fail "$1: $f differs from the single process's"
        done < "$work/serial.files"
    }
    # One rank under mpirun is a single process (no distribution): the same files.
    mpi 1 "$tool" "$work/mpi_fields.json" --no-cache --quiet --output-root "$work/np1" > "$work/np1.log" 2>&1 ||
        { cat "$work/np1.log"; fail "mpirun -np 1 failed"; }
    same_fields "np 1" "$(run_dir "$work/np1")"
    echo "np 1: $(wc -l < "$work/serial.files") channel files identical to the single process's"
    for n in 2 3; do
        mpi "$n" "$tool" "$work/mpi_fields.json" --no-cache --quiet --output-root "$work/np$n" > "$work/np$n.log" 2>&1 ||
            { cat "$work/np$n.log"; fail "mpirun -np $n failed"; }
        dist=$(run_dir "$work/np$n")
        same_fields "np $n" "$dist"
        grep -q "\"ranks\": $n" "$dist/manifest.json" || fail "np $n: the manifest does not record $n ranks"
        grep -q '"load_balance"' "$dist/manifest.json" || fail "np $n: no load balance in the manifest"
        grep -q '"bvh_visits"' "$dist/manifest.json" || fail "np $n: the BVH fields were not planned from BVH visits"
        # The parallel path wrote the files: each rank its slab's points x 36 bytes (float64
        # distance and gradient, int32 closest triangle), together every byte of every file.
        python3 - "$dist" "$n" <<'PY' || fail "np $n: the field files were not written by the ranks with MPI-IO"
import json, os, sys
run, ranks = sys.argv[1], int(sys.argv[2])
fields = json.load(open(os.path.join(run, "manifest.json")))["distributed"]["fields"]
assert len(fields) == 4, f"{len(fields)} distributed fields, expected 4"
for f in fields:
    assert f.get("write") == "mpi-io", f"{f['lattice']}: write is {f.get('write')}"
    assert [s["written_by"] for s in f["slabs"]] == list(range(ranks)), f["slabs"]
    assert all(s["write_bytes"] == 36 * s["points"] > 0 for s in f["slabs"]), f["slabs"]
    assert sum(s["write_bytes"] for s in f["slabs"]) == f["write_bytes"]
raw = sum(os.path.getsize(os.path.join(d, x)) for d, _, xs in os.walk(run) for x in xs if x.endswith(".raw"))
written = sum(f["write_bytes"] for f in fields)
assert written == raw, f"the ranks wrote {written} bytes, the channel files hold {raw}"
print(f"np {ranks}: {written} bytes written by the ranks with MPI-IO:",
      [[s["write_bytes"] for s in f["slabs"]] for f in fields])
PY
        echo "np $n: $(wc -l < "$work/serial.files") channel files identical to the single process's"
    done
    # A rank that cannot open the files (a node without the shared file system) leaves its
    # slab to rank 0, which holds the whole field: the same files.
    SDF_MPI_FAIL_RANK=1 SDF_MPI_FAIL_STAGE=open mpi 3 "$tool" "$work/mpi_fields.json" --no-cache --quiet \
        --output-root "$work/noopen" > "$work/noopen.log" 2>&1 || { cat "$work/noopen.log"; fail "rank 1 without the files: the run failed"; }
    dist=$(run_dir "$work/noopen")
    same_fields "rank 1 without the files" "$dist"
    python3 - "$dist" <<'PY' || fail "rank 1 without the files: rank 0 did not write its slab"
import json, os, sys
for f in json.load(open(os.path.join(sys.argv[1], "manifest.json")))["distributed"]["fields"]:
    assert [s["written_by"] for s in f["slabs"]] == [0, 0, 2], f["slabs"]
    assert "SDF_MPI_FAIL_STAGE=open" in f["slabs"][1]["why"], f["slabs"][1]
PY
    echo "np 3, rank 1 cannot open the files: rank 0 wrote its slab; the same channel files"
    # A sweep distributed run by run: the same tree, the same fields.
    mpi 2 "$tool" "$work/mpi_fields.json" --no-cache --quiet --distribute runs --output-root "$work/runs" > "$work/runs.log" 2>&1 ||
        { cat "$work/runs.log"; fail "mpirun -np 2 --distribute runs failed"; }
    dist=$(run_dir "$work/runs")
    (cd "$dist" && find . | sort) | diff "$work/serial.tree" - || fail "--distribute runs: another results tree"
    same_fields "--distribute runs" "$dist"
    grep -q '"mode": "runs"' "$dist/manifest.json" || fail "--distribute runs: the manifest does not say so"
    echo "--distribute runs: the same results tree and channel files"
    exit 0
fi

if [ "$case_name" = gpu ]; then
    # Issue 36: two GPUs, as ranks and as one process's devices, give one GPU's files byte for
    # byte, each rank on its own device. Skipped (77) below two visible GPUs.
    gpus=$(nvidia-smi -L 2>/dev/null | grep -c '^GPU' || true)
    if [ -n "${CUDA_VISIBLE_DEVICES+set}" ]; then  # nvidia-smi lists every GPU; CUDA sees only these
        visible=$(printf '%s\n' "$CUDA_VISIBLE_DEVICES" | tr ',' '\n' | grep -c . || true)
        if [ "$visible" -lt "${gpus:-0}" ]; then gpus=$visible; fi
    fi
    [ "${gpus:-0}" -ge 2 ] || { echo "$gpus GPU(s) visible, this test needs 2: skipped"; exit 77; }
    sed -e 's/"backend": "cpu"/"backend": "cuda"/' -e 's/\[11, 9, 13\]/[96, 96, 96]/' -e 's/\[8, 7, 18\]/[64, 64, 128]/' \
        "$work/mpi_fields.json" > "$work/gpu.json"
    # min_points_per_device 1: these lattices are below the default split threshold.
    sed 's/"backend": "cuda"/"backend": "cuda", "devices": "all", "min_points_per_device": 1/' "$work/gpu.json" > "$work/gpu_all.json"
    sed -i 's/"name": "mpi_fields"/"name": "mpi_fields_all"/' "$work/gpu_all.json"
    "$tool" "$work/gpu.json" --no-cache --quiet --output-root "$work/one" > "$work/one.log" 2>&1 || { cat "$work/one.log"; fail "one GPU failed"; }
    one=$(run_dir "$work/one")
    (cd "$one" && find . -name '*.raw' | sort) > "$work/one.files"
    [ "$(wc -l < "$work/one.files")" -eq 12 ] || fail "expected 12 channel files"
    mpi 2 "$tool" "$work/gpu.json" --no-cache --quiet --output-root "$work/np2" > "$work/np2.log" 2>&1 ||
        { cat "$work/np2.log"; fail "mpirun -np 2 on GPUs failed"; }
    "$tool" "$work/gpu_all.json" --no-cache --quiet --output-root "$work/all" > "$work/all.log" 2>&1 ||
        { cat "$work/all.log"; fail "devices all failed"; }
    np2=$(run_dir "$work/np2") all=$(run_dir_of "$work/all" mpi_fields_all)
    while read -r f; do
        cmp "$one/$f" "$np2/$f" || fail "np 2: $f differs from one GPU's"
        # The config's name, renamed for the devices run, names its sweep points' folders.
        cmp "$one/$f" "$all/${f//mpi_fields-/mpi_fields_all-}" || fail "devices all: $f differs from one GPU's"
    done < "$work/one.files"
    python3 - "$np2" "$all" <<'PY' || fail "the provenance does not put each slab on its own GPU"
import json, os, sys
fields = json.load(open(os.path.join(sys.argv[1], "manifest.json")))["distributed"]["fields"]
for f in fields:
    buses = [s["device"]["pci_bus_id"] for s in f["slabs"]]
    assert len(set(buses)) == 2, f"np 2: slabs on {buses}"
metrics = open(os.path.join(sys.argv[2], "metrics.json")).read()
assert '"split": true' in metrics.replace('"split":true', '"split": true'), "devices all: no field was split"
print("np 2: each rank on its own GPU;", len(fields), "fields")
PY
    echo "GPUs: np 2 and devices all give one GPU's $(wc -l < "$work/one.files") channel files byte for byte"
    exit 0
fi

if [ "$case_name" = narrow_band ]; then
    # One process samples the band sparsely; over ranks, brute force bands by post-processing
    # and the BVH skips bricks outside the band (its skip counters depend on the bricks, which
    # a slab cuts, so they are checked for consistency).
    sed 's/"progress": false}/"progress": false, "band_width": 0.12}/' "$work/mpi_fields.json" > "$work/band.json"
    grep -q '"band_width": 0.12' "$work/band.json" || fail "no band in the config"
    "$tool" "$work/band.json" --no-cache --quiet --output-root "$work/serial" > "$work/serial.log"
    mpi 3 "$tool" "$work/band.json" --no-cache --quiet --output-root "$work/np3" > "$work/np3.log" 2>&1 ||
        { cat "$work/np3.log"; fail "mpirun -np 3 with a narrow band failed"; }
    serial=$(run_dir "$work/serial") dist=$(run_dir "$work/np3")
    (cd "$serial" && find . -name '*.raw' | sort) > "$work/serial.files"
    [ "$(wc -l < "$work/serial.files")" -eq 12 ] || fail "expected 12 channel files"
    while read -r f; do
        cmp "$serial/$f" "$dist/$f" || fail "narrow band, np 3: $f differs from the single process's"
    done < "$work/serial.files"
    python3 - "$serial" "$dist" <<'PY' || fail "narrow band, np 3: the sampler reports differ from the single process's"
import json, os, sys
def fields(run):  # field name -> (its sampler report, its lattice's points)
    metrics = json.load(open(os.path.join(run, "metrics.json")))
    return {p["name"] + "/" + f["name"]: (f["sampler"], f["lattice"]["points"])
            for p in metrics["points"] for f in p["metrics"]["fields"]}
one, three = fields(sys.argv[1]), fields(sys.argv[2])
assert sorted(one) == sorted(three) and len(one) == 4, (sorted(one), sorted(three))
for name, (s1, points) in sorted(one.items()):
    s3 = three[name][0]
    b1, b3 = s1["band"], s3["band"]
    assert b1["points_in_band"] + b1["points_outside"] == points, (name, b1)
    assert b1["points_outside"] > 0 and b1["points_in_band"] > 0, (name, b1)
    for key in ("width", "points_in_band", "points_outside"):
        assert b1[key] == b3[key], (name, key, b1, b3)
    # One process samples the band sparsely (only the blocks within W of a triangle), the
    # ranks densely, slab by slab: the same bytes (compared above), reached two ways.
    assert b1["how"].startswith("sparse"), (name, b1)
    assert not b3["how"].startswith("sparse"), (name, b3)
    slabs = s3["distributed"]["slabs"]
    assert len(slabs) == 3 and sum(s["points_computed"] for s in slabs) == s3["points_computed"], (name, slabs)
    c3 = s3["search_certificate"]
    if "probes" in b3:  # the BVH's brick skip: every point computed or skipped, on every rank
        assert s3["points_computed"] + b3["points_skipped"] == points, (name, s3)
        assert c3["points"] == s3["points_computed"], (name, c3)
    else:  # brute force computes every point
        assert s3["points_computed"] == points, (name, s3)
    print(f"{name}: {b1['points_in_band']} of {points} points in the band on 1 (sparse) and 3 ranks (dense); "
          f"the ranks computed {s3['points_computed']}")
PY
    echo "narrow band, np 3: 12 channel files identical to the single process's, the same band counters"
    exit 0
fi

if [ "$case_name" = ci_smoke ]; then
    config=$(dirname "$0")/../../configs/ci_smoke.json
    mpi 2 "$tool" "$config" --no-cache --quiet --check --output-root "$work/smoke" > "$work/smoke.log" 2>&1 ||
        { cat "$work/smoke.log"; fail "ci_smoke on 2 ranks failed or failed its check"; }
    grep -q '"ranks": 2' "$(run_dir_of "$work/smoke" ci_smoke)/manifest.json" || fail "ci_smoke: not distributed"
    grep PASSED "$work/smoke.log"
    exit 0
fi

if [ "$case_name" = mismatch ]; then
    # expect_refusal LABEL PATTERN -- MPIEXEC ARGS: fails within 60 s, names PATTERN, runs nothing.
    expect_refusal() {
        local label=$1 pattern=$2 status=0
        shift 3
        timeout -s KILL 60 "$mpiexec" --oversubscribe "$@" > "$work/mismatch.log" 2>&1 || status=$?
        [ "$status" -ne 0 ] || { cat "$work/mismatch.log"; fail "$label: the run succeeded"; }
        [ "$status" -ne 137 ] || { cat "$work/mismatch.log"; fail "$label: the ranks hung (killed after 60 s)"; }
        grep -qF -- "$pattern" "$work/mismatch.log" || { cat "$work/mismatch.log"; fail "$label: no message naming $pattern"; }
        [ ! -d "$work/mm/mpi_fields" ] || [ -z "$(ls "$work/mm/mpi_fields")" ] || fail "$label: a run directory was left"
        echo "$label: every rank stopped: $(grep -m1 'error:' "$work/mismatch.log")"
    }
    common=(--no-cache --quiet --output-root "$work/mm")
    expect_refusal "--distribute slabs on rank 0, runs on ranks 1 and 2" \
        '--distribute: rank 0 has "slabs", ranks 1, 2 have "runs"' -- \
        -np 1 "$tool" "$work/mpi_fields.json" "${common[@]}" : -np 2 "$tool" "$work/mpi_fields.json" "${common[@]}" --distribute runs
    sed 's/"bvh"/"brute_force"/' "$work/mpi_fields.json" > "$work/other.json"
    cp "$work/other.json" "$work/mpi_fields_copy.json"
    expect_refusal "another config on rank 1" 'config: rank 0 has' -- \
        -np 1 "$tool" "$work/mpi_fields.json" "${common[@]}" : -np 1 "$tool" "$work/mpi_fields_copy.json" "${common[@]}"
    exit 0
fi

if [ "$case_name" = failure ]; then
    # label, failing rank, log[, "runs"]; the run must have failed and published nothing. A
    # killed root may leave its hidden staging directory (the next run removes it), never a run
    # directory. The injected failures strike at the first slab, so the cache stays empty;
    # distributed by runs, the root's own run completes, and its fields may be cached; a
    # failure in the parallel write comes after the field was sampled and cached whole.
    expect_clean_failure() {
        local label=$1 log=$3
        [ ! -d "$work/out/mpi_fields" ] || [ -z "$(ls "$work/out/mpi_fields")" ] || fail "$label: a run directory was left: $(ls "$work/out/mpi_fields")"
        [ "${4:-}" = runs ] || [ "${4:-}" = cached ] || ! find "$work/cache" -name entry.json -not -path '*/.*' 2>/dev/null | grep -q . ||
            fail "$label: the cache holds an entry of the failed run"
        grep -Eq "rank $2[^0-9].*$(uname -n)|$(uname -n).*rank $2[^0-9]" "$log" ||
            grep -Eq "rank $2 .*node" "$log" || { cat "$log"; fail "$label: the message does not name rank $2 and its host"; }
    }
    for failing in 1 0; do
        if SDF_MPI_FAIL_RANK=$failing mpi 2 "$tool" "$work/mpi_fields.json" --quiet --cache-dir "$work/cache" \
               --output-root "$work/out" > "$work/fail$failing.log" 2>&1; then
            fail "the run with rank $failing failing succeeded"
        fi
        grep -q "injected failure" "$work/fail$failing.log" || { cat "$work/fail$failing.log"; fail "no error message"; }
        expect_clean_failure "rank $failing errs" "$failing" "$work/fail$failing.log"
        [ ! -d "$work/out/mpi_fields" ] || [ -z "$(ls -A "$work/out/mpi_fields")" ] || fail "rank $failing errs: staging left behind"
        echo "rank $failing errs: the run failed cleanly: $(grep -m1 'error:' "$work/fail$failing.log")"
    done
    if SDF_MPI_FAIL_RANK=1 mpi 2 "$tool" "$work/mpi_fields.json" --quiet --cache-dir "$work/cache" --distribute runs \
           --output-root "$work/out" > "$work/runs.log" 2>&1; then
        fail "the run by runs with rank 1 failing succeeded"
    fi
    expect_clean_failure "--distribute runs, rank 1 errs" 1 "$work/runs.log" runs
    rm -rf "$work/cache"
    echo "--distribute runs, rank 1 errs: the run failed cleanly: $(grep -m1 'error:' "$work/runs.log")"
    if SDF_MPI_FAIL_RANK=2 SDF_MPI_FAIL_MODE=kill mpi 3 "$tool" "$work/mpi_fields.json" --quiet --cache-dir "$work/cache" \
           --output-root "$work/out" > "$work/dies.log" 2>&1; then
        fail "the run with a dying rank succeeded"
    fi
    expect_clean_failure "rank 2 dies" 2 "$work/dies.log"
    echo "rank 2 dies: the run failed cleanly"
    # Failures while the ranks write the field files (MPI-IO): the fields were sampled and
    # cached whole before; the run fails and publishes nothing.
    for case in "1 2 err" "0 3 err" "2 3 kill"; do
        read -r failing ranks mode <<< "$case"
        rm -rf "$work/cache"
        if SDF_MPI_FAIL_RANK=$failing SDF_MPI_FAIL_STAGE=write SDF_MPI_FAIL_MODE=$mode mpi "$ranks" "$tool" \
               "$work/mpi_fields.json" --quiet --cache-dir "$work/cache" --output-root "$work/out" > "$work/write.log" 2>&1; then
            fail "the run with rank $failing of $ranks failing ($mode) in the parallel write succeeded"
        fi
        [ "$mode" = kill ] || grep -q "parallel write of field fields/.*injected failure at the write stage" "$work/write.log" ||
            { cat "$work/write.log"; fail "rank $failing of $ranks: not a write-stage failure"; }
        expect_clean_failure "rank $failing of $ranks fails ($mode) in the write" "$failing" "$work/write.log" cached
        echo "rank $failing of $ranks fails ($mode) in the parallel write: the run failed cleanly: $(grep -m1 'error:' "$work/write.log" || true)"
    done
    exit 0
fi
fail "unknown case $case_name"
