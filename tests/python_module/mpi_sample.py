"""sdf_lattices.sample() under mpirun: collective over the ranks, bit for bit one process's.

Run by CTest (python_module_mpi_np2, _np3) as `mpirun --oversubscribe -np N python3 -m pytest
THIS_FILE`: every rank runs every test, as every rank of a user's script runs the same code.
The truth is the same call with distributed=False on the same rank: the plain single-process
sampler, with no MPI message (test_sdf_lattices.py checks that one against run-experiment's
field files, bit for bit). Failures are injected with SDF_MPI_FAIL_RANK, the hook of
run-experiment's mpi_failure test. Not named test_*.py: the single-process suite does not
collect it.
"""
import os

import numpy as np
import pytest

import sdf_lattices as sl

RANK = int(os.environ.get("OMPI_COMM_WORLD_RANK", os.environ.get("PMI_RANK", "0")))
SIZE = int(os.environ.get("OMPI_COMM_WORLD_SIZE", os.environ.get("PMI_SIZE", "1")))

pytestmark = pytest.mark.skipif(SIZE < 2 or not sl.distributed()["mpi"],
                                reason="needs an MPI build and mpirun -np 2 or more")

# (lattice, resolution, sampler arguments): both lattices, both methods, both precisions, both
# BCC strategies, and a lattice with fewer z-planes than 3 ranks (an empty slab).
CASES = {
    "cc-brute_force-double": ("cc", [11, 9, 13], {"method": "brute_force", "precision": "double"}),
    "cc-bvh-float": ("cc", [11, 9, 13], {"method": "bvh"}),
    "bcc-brute_force-float": ("bcc", [8, 7, 18], {"method": "brute_force"}),
    "bcc-bvh-double": ("bcc", [8, 7, 18], {"method": "bvh", "precision": "double"}),
    "bcc-bvh-double_resolution": ("bcc", [8, 7, 18], {"method": "bvh", "bcc_strategy": "double_resolution"}),
    "cc-bvh-two_planes": ("cc", [6, 5, 2], {"method": "bvh"}),
}


@pytest.fixture(scope="module")
def torus():
    return sl.load_mesh("shape:torus")


def arrays(field):
    """Every array of the field: values, gradient, triangle, per sub-grid."""
    out = []
    for a in (field.values, field.gradient, field.triangle):
        out += list(a) if isinstance(a, tuple) else [a]
    return out


def same_bits(a, b):
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


@pytest.fixture
def fail_rank():
    """Sets SDF_MPI_FAIL_RANK for one call, and always removes it."""
    def set_rank(rank):
        os.environ["SDF_MPI_FAIL_RANK"] = str(rank)
    yield set_rank
    os.environ.pop("SDF_MPI_FAIL_RANK", None)


def test_distributed_describes_the_ranks():
    info = sl.distributed()
    assert (info["rank"], info["size"]) == (RANK, SIZE)
    assert info["started_by"] == "sdf_lattices"
    assert info["local_size"] == SIZE and info["threads"] >= 1 and info["host"]
    if RANK == 0:
        assert [p["rank"] for p in info["processes"]] == list(range(SIZE))
    else:
        assert "processes" not in info


@pytest.mark.parametrize("case", CASES)
def test_distributed_sample_equals_one_process(torus, case):
    lattice, resolution, options = CASES[case]
    args = dict(lattice=lattice, resolution=resolution, backend="cpu", **options)
    field = sl.sample(torus, **args)
    alone = sl.sample(torus, distributed=False, **args)
    assert "distributed" not in alone.sampler
    assert field.notation == alone.notation and field.lattice_info == alone.lattice_info
    for got, want in zip(arrays(field), arrays(alone), strict=True):
        assert same_bits(got, want)

    # The provenance: every rank's slab, contiguous, covering the lattice.
    d = field.sampler["distributed"]
    assert d["ranks"] == SIZE and d["collective"] is True and d["lattice"] == field.notation
    assert d["cost_estimate"] == ("bvh_visits" if options["method"] == "bvh" else "points")
    slabs = d["slabs"]
    assert [s["rank"] for s in slabs] == list(range(SIZE))
    assert slabs[0]["z_planes"][0] == 0 and slabs[-1]["z_planes"][1] == resolution[2] // (2 if lattice == "bcc" else 1)
    assert all(a["z_planes"][1] == b["z_planes"][0] for a, b in zip(slabs, slabs[1:]))
    assert sum(s["points"] for s in slabs) == field.num_points
    assert all(s["seconds"] >= 0 and s["host"] for s in slabs)
    assert field.sampler["points_computed"] == field.num_points
    if case == "cc-bvh-two_planes" and SIZE > 2:
        assert any(s["points"] == 0 for s in slabs)  # more ranks than planes: an empty slab, still answered
    assert field.seconds > 0


@pytest.mark.parametrize("failing", ["last", "root"])
def test_a_failing_rank_raises_on_every_rank(torus, fail_rank, failing):
    rank = 0 if failing == "root" else SIZE - 1
    fail_rank(rank)
    with pytest.raises(RuntimeError, match=rf"distributed sampling of 11x9x13 failed on 1 of {SIZE} ranks: "
                                           rf"rank {rank} \(host [^)]+\): injected failure \(SDF_MPI_FAIL_RANK={rank}\)"):
        sl.sample(torus, lattice="cc", resolution=[11, 9, 13], backend="cpu", method="bvh")
    # The exchange ended in step on every rank: the next call works.
    os.environ.pop("SDF_MPI_FAIL_RANK")
    field = sl.sample(torus, lattice="cc", resolution=[11, 9, 13], backend="cpu", method="bvh")
    assert field.sampler["distributed"]["ranks"] == SIZE


def test_another_argument_on_one_rank_raises_on_every_rank(torus):
    resolution = [11, 9, 14] if RANK == 1 else [11, 9, 13]
    with pytest.raises(RuntimeError, match=r"failed on 1 of \d+ ranks: rank 1 \(host [^)]+\): called with another "
                                           r"lattice than rank 0 .*resolution \[11,9,14\] here, .*resolution \[11,9,13\] on rank 0"):
        sl.sample(torus, lattice="cc", resolution=resolution, backend="cpu")


def test_another_mesh_on_one_rank_raises_on_every_rank(torus):
    mesh = sl.load_mesh("shape:sphere") if RANK == SIZE - 1 else torus
    with pytest.raises(RuntimeError, match=rf"rank {SIZE - 1} \(host [^)]+\): called with another mesh than rank 0"):
        sl.sample(mesh, lattice="cc", resolution=[6, 6, 6], backend="cpu")


def test_a_bad_argument_everywhere_is_the_single_process_error(torus):
    with pytest.raises(ValueError) as alone:
        sl.sample(torus, lattice="cc", resolution=[1, 9, 13], backend="cpu", distributed=False)
    with pytest.raises(ValueError) as together:
        sl.sample(torus, lattice="cc", resolution=[1, 9, 13], backend="cpu")
    assert str(together.value) == str(alone.value)


def test_a_bad_argument_on_one_rank_raises_on_every_rank(torus):
    resolution = [1, 9, 13] if RANK == SIZE - 1 else [11, 9, 13]
    with pytest.raises(RuntimeError, match=rf"rank {SIZE - 1} \(host [^)]+\): sample\(\): key 'lattice.resolution'"):
        sl.sample(torus, lattice="cc", resolution=resolution, backend="cpu")
