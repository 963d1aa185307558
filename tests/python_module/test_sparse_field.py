"""sample(mesh, ..., band=W) and SDF.sample(..., band=W): a SparseField (issue 35), checked
against the dense field of band_width=W (the existing path, sampled independently): to_dense()
equal to it bit for bit, the band's points holding its values at its points, write() read back
by pyopenvdb (Debian python3-openvdb), and the refusals."""
import warnings

import numpy as np
import pytest

import sdf_lattices as sl
from test_sdf_lattices import box_arrays, same_bits

CASES = [  # (id, lattice, resolution, sampler keywords, skip_face)
    ("cc_float", "cc", (23, 19, 17), {"precision": "float"}, None),
    ("cc_double", "cc", 20, {"precision": "double"}, None),
    ("bcc_float", "bcc", (12, 10, 18), {"precision": "float"}, None),
    ("cc_open_winding", "cc", 22, {"sign": "winding"}, 0),
    ("bcc_open_winding_double", "bcc", 11, {"sign": "winding", "precision": "double"}, 0),
]
W = 0.2


def grids(arrays):
    return list(arrays) if isinstance(arrays, tuple) else [arrays]


@pytest.fixture(scope="module", params=CASES, ids=[c[0] for c in CASES])
def pair(request):
    _, lattice, resolution, keywords, skip_face = request.param
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", sl.MeshWarning)  # the open box, on purpose
        mesh = sl.Mesh(*box_arrays(skip_face=skip_face), name="box")
    sparse = sl.sample(mesh, lattice, resolution, band=W, backend="cpu", threads=2, **keywords)
    dense = sl.sample(mesh, lattice, resolution, band_width=W, backend="cpu", threads=2, **keywords)
    return mesh, lattice, resolution, keywords, sparse, dense


def test_to_dense_is_the_band_width_field_bit_for_bit(pair):
    *_, sparse, dense = pair
    d = sparse.to_dense()
    assert isinstance(d, sl.Field) and d.resolution == dense.resolution
    for a, b in zip(grids(d.values), grids(dense.values)):
        assert same_bits(a, b)
    for a, b in zip(grids(d.gradient), grids(dense.gradient)):
        assert same_bits(a, b)
    for a, b in zip(grids(d.triangle), grids(dense.triangle)):
        assert same_bits(a, b)


def test_band_points_hold_the_dense_values_at_their_positions(pair):
    *_, sparse, dense = pair
    n = len(sparse)
    assert n == sum(int((t != -2).sum()) for t in grids(dense.triangle)) > 0
    for name in ("distance", "triangle", "subgrid"):
        assert getattr(sparse, name).shape == (n,)
    for name in ("points", "indices", "gradient"):
        assert getattr(sparse, name).shape == (n, 3)
    values, gradient, triangle = grids(dense.values), grids(dense.gradient), grids(dense.triangle)
    positions = grids(dense.points())
    i, j, k = sparse.indices.T
    seen = 0
    for g in range(len(values)):
        at = sparse.subgrid == g
        gi, gj, gk = k[at], j[at], i[at]
        assert same_bits(sparse.distance[at], values[g][gi, gj, gk])
        assert same_bits(sparse.gradient[at], gradient[g][gi, gj, gk])
        assert same_bits(sparse.triangle[at], triangle[g][gi, gj, gk])
        assert same_bits(sparse.points[at], positions[g][gi, gj, gk])
        assert (triangle[g][gi, gj, gk] != -2).all() and (np.abs(sparse.distance[at]) <= W).all()
        seen += int(at.sum())
    assert seen == n
    assert len({tuple(r) for r in np.column_stack([sparse.subgrid, sparse.indices])}) == n  # each point once


def test_lattice_description_is_the_dense_fields(pair):
    *_, sparse, dense = pair
    assert sparse.width == W and sparse.lattice == dense.lattice and sparse.resolution == dense.resolution
    assert sparse.origin == dense.origin and sparse.spacing == dense.spacing and sparse.num_points == dense.num_points
    assert sparse.active_blocks == sparse.counts["active_blocks"] > 0
    assert sparse.nbytes > 0 and "SparseField" in repr(sparse)


def test_sdf_sample_band_equals_sample_band(pair):
    mesh, lattice, resolution, keywords, sparse, _ = pair
    s = sl.SDF(mesh, backend="cpu", threads=2, **keywords).sample(lattice, resolution, band=W)
    assert isinstance(s, sl.SparseField)
    for name in ("distance", "gradient", "triangle", "indices", "subgrid"):
        assert same_bits(getattr(s, name), getattr(sparse, name))


def test_write_vdb_read_by_pyopenvdb(pair, tmp_path):
    *_, sparse, dense = pair
    if not sl.build_info()["optional"]["openvdb"]["found"]:
        with pytest.raises(RuntimeError, match="OpenVDB"):
            sparse.write(str(tmp_path / "band.vdb"))
        return
    pyopenvdb = pytest.importorskip("pyopenvdb")
    path = str(tmp_path / "band.vdb")
    assert sparse.write(path) == [path]
    with pytest.raises(RuntimeError, match="already exists"):
        sparse.write(path)
    grids_read = {g.name: g for g in pyopenvdb.readAll(path)[0]}
    parts = [""] if sparse.lattice == "cc" else ["_primary", "_secondary"]
    assert set(grids_read) == {n + p for p in parts for n in ("distance", "gradient")}
    for g, part in enumerate(parts):
        ls = grids_read["distance" + part]
        assert str(ls.gridClass) == "level set" and ls.background == np.float32(W)
        at = sparse.subgrid == g
        assert ls.activeVoxelCount() == int(at.sum())
        acc = ls.getConstAccessor()
        for (i, j, k), d in zip(sparse.indices[at][:500], sparse.distance[at][:500]):
            value, active = acc.probeValue((int(i), int(j), int(k)))
            assert active and value == np.float32(d)
    assert set(sparse.to_openvdb()) == set(grids_read)
    # closest_triangle=True adds Int32Grids, which Debian's pyopenvdb 10 cannot read: the other grids still read
    # by name, and the file names the new ones.
    with_triangles = str(tmp_path / "triangles.vdb")
    sparse.write(with_triangles, closest_triangle=True)
    again = pyopenvdb.read(with_triangles, "distance" + parts[0])
    assert again.activeVoxelCount() == grids_read["distance" + parts[0]].activeVoxelCount()
    content = open(with_triangles, "rb").read()
    assert all(("closest_triangle" + p).encode() in content for p in parts)


def test_other_formats_are_refused_naming_the_way(pair, tmp_path):
    *_, sparse, _ = pair
    with pytest.raises(ValueError, match=r"\.vdb.*to_dense\(\)\.write"):
        sparse.write(str(tmp_path / "band.vti"))
    assert not list(tmp_path.iterdir())


def test_to_dense_refused_with_the_size_past_the_memory_check(pair, monkeypatch):
    *_, sparse, _ = pair
    monkeypatch.setenv("SDF_MEMORY_AVAILABLE", "1000")
    with pytest.raises(RuntimeError, match=r"to_dense.*densifying"):
        sparse.to_dense()


def test_band_refusals():
    mesh = sl.Mesh(*box_arrays(), name="box")
    with pytest.raises(ValueError, match="band_width"):
        sl.sample(mesh, resolution=8, band=0.1, band_width=0.1, backend="cpu")
    with pytest.raises(ValueError, match="band"):
        sl.sample(mesh, resolution=8, band=-1.0, backend="cpu")
    with pytest.raises(ValueError, match="signed"):
        sl.sample(mesh, resolution=8, band=0.1, sign="none", backend="cpu")
    with pytest.raises(TypeError, match="unexpected keyword"):
        sl.SDF(mesh, backend="cpu").sample(resolution=8, band=0.1, precision="float")


def test_without_band_the_dense_field_is_unchanged():
    mesh = sl.Mesh(*box_arrays(), name="box")
    assert isinstance(sl.sample(mesh, resolution=8, backend="cpu"), sl.Field)
    assert isinstance(sl.SDF(mesh, backend="cpu").sample(resolution=8), sl.Field)


def test_memory_grows_with_the_band():
    mesh = sl.Mesh(*box_arrays(), name="box")
    sparse = sl.sample(mesh, resolution=96, band=0.03, backend="cpu", threads=2)
    dense_bytes = sparse.num_points * (8 + 24 + 4)
    assert sparse.nbytes < dense_bytes / 4, (sparse.nbytes, dense_bytes)
