"""SparseField.write(".nvdb"): the sparse band's NanoVDB level set (harness/io/sparse_nvdb_file.h),
in builds with NanoVDB (else refused, naming it). Its values are checked against the dense band
with NanoVDB's own reader in tests/harness/sparse_nvdb_test.cpp; here, that Python writes the
file NanoVDB's format names (the file magic "NanoVDB2", the grids named as the .vdb's) and
refuses what it cannot write."""
import warnings

import pytest

import sdf_lattices as sl
from test_sdf_lattices import box_arrays


@pytest.mark.parametrize("lattice,resolution,names", [("cc", 18, [b"distance"]),
                                                      ("bcc", 10, [b"distance_primary", b"distance_secondary"])])
def test_write_nvdb(tmp_path, lattice, resolution, names):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sl.MeshWarning)
        mesh = sl.Mesh(*box_arrays(), name="box")
    sparse = sl.sample(mesh, lattice, resolution, band=0.2, backend="cpu", threads=2)
    path = str(tmp_path / "band.nvdb")
    try:
        files = sparse.write(path)
    except RuntimeError as e:
        assert "NanoVDB" in str(e)
        return
    assert files == [path]
    with open(path, "rb") as f:
        data = f.read()
    assert data[:8] == b"NanoVDB2"
    for name in names:
        assert name + b"\0" in data
    with pytest.raises(RuntimeError, match="already exists"):
        sparse.write(path)
    assert sparse.write(path, overwrite=True) == [path]
    with pytest.raises(ValueError, match="distance grids only"):
        sparse.write(str(tmp_path / "t.nvdb"), closest_triangle=True)
