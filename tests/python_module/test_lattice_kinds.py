"""The lattice table (kernels/lattice/lattice_kinds.h) as the module exposes it,
_core.lattice_kinds(): the run schema's $defs.lattice_type lists exactly its names in its
order (scripts/sdf_report and scripts/scaling-run take their choices from there), each row's
parts are as many as its cosets, and read_field reads every kind's .npz and .vti through the
table: values and gradients back bit for bit, the kind's name back, and a .npz of an unknown
kind refused with the table's names."""
import os
import sys

import numpy as np
import pytest

import sdf_lattices as sl
from sdf_lattices import _core
from test_sdf_lattices import box_arrays, same_bits

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "scripts"))
from sdf_report.schema import lattice_types  # noqa: E402  (the report's own reading of the run schema)

KINDS = _core.lattice_kinds()


def grids(arrays):
    """A field's arrays as a list of grids: [cc] or [primary, secondary]."""
    return list(arrays) if isinstance(arrays, tuple) else [arrays]


@pytest.fixture(scope="module")
def box():
    v, f = box_arrays()
    return sl.Mesh(v, f, name="box")


def test_the_run_schema_names_the_tables_kinds_in_its_order():
    assert lattice_types() == [k["name"] for k in KINDS]


def test_every_row_is_whole():
    assert KINDS[0]["cosets"] == 1  # the Cartesian kind first: the report draws it solid, the others dashed
    assert len({k["name"] for k in KINDS}) == len(KINDS)
    for k in KINDS:
        assert k["label"] and k["description"], k
        assert len(k["parts"]) == k["cosets"] >= 1, k
        if k["cosets"] == 1:  # one grid: its arrays and files unsuffixed
            assert k["parts"] == [""], k
        else:  # every part named, once
            assert all(k["parts"]) and len(set(k["parts"])) == k["cosets"], k


@pytest.mark.parametrize("ext", ["npz", "vti"])
@pytest.mark.parametrize("kind", [k["name"] for k in KINDS])
def test_read_field_reads_every_kind_through_the_table(tmp_path, box, kind, ext):
    if ext == "vti":
        pytest.importorskip("vtk")
    field = sl.sample(box, lattice=kind, resolution=6, backend="cpu", precision="double")
    path = str(tmp_path / f"f.{ext}")
    field.write(path, dtype="float64")
    back = sl.read_field(path)
    assert back.lattice == kind and back.resolution == field.resolution
    assert back.origin == field.origin and back.spacing == field.spacing
    for name in ("values", "gradient"):
        ours, theirs = grids(getattr(back, name)), grids(getattr(field, name))
        assert len(ours) == len(theirs) == next(k["cosets"] for k in KINDS if k["name"] == kind)
        for x, y in zip(ours, theirs):
            assert same_bits(x, y), (kind, ext, name)


def test_a_npz_of_an_unknown_kind_is_refused_with_the_tables_names(tmp_path):
    path = str(tmp_path / "hex.npz")
    np.savez(path, lattice=np.array("hex"), distance=np.zeros((2, 2, 2)), origin=np.zeros(3), spacing=np.array(1.0))
    names = [f"'{k['name']}'" for k in KINDS]
    known = f"neither {names[0]} nor {names[1]}" if len(names) == 2 else "none of " + ", ".join(names)
    with pytest.raises(ValueError, match=rf"hex\.npz: not an sdf_lattices \.npz field \(its 'lattice' entry is missing or {known}\)"):
        sl.read_field(path)
