"""sample(mesh, ..., band=W) and SDF.sample(..., band=W): a SparseField (issue 35), checked
against the dense field of band_width=W (the existing path, sampled independently): to_dense()
equal to it bit for bit, the band's points holding its values at its points, write() read back
by pyopenvdb (Debian python3-openvdb), and the refusals."""
import json
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
    read_back = sl.read_field(path)  # the grids, through pyopenvdb
    assert set(read_back) == set(grids_read)
    assert read_back["distance" + parts[0]].activeVoxelCount() == grids_read["distance" + parts[0]].activeVoxelCount()
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


def test_sparse_field_file_round_trip_and_densified_equals_the_dense_field(pair, tmp_path):
    """write(.json) and read_field: the band back, array for array (float64), and densified, the dense
    band_width=W field (float64 bit for bit; float32: the dense field written and read as float32)."""
    *_, sparse, dense = pair
    path = str(tmp_path / "band.json")
    files = sparse.write(path, dtype="float64")
    assert files[0] == path and len(files) == 8  # header, 7 channels (gradient included)
    back = sl.read_field(path)
    assert isinstance(back, sl.SparseField) and len(back) == len(sparse)
    for name in ("distance", "gradient", "triangle", "points", "indices", "subgrid"):
        assert same_bits(getattr(back, name), getattr(sparse, name)), name
    assert back.counts == sparse.counts and back.width == sparse.width and back.mesh == sparse.mesh
    d = back.to_dense()
    for a, b in zip(grids(d.values), grids(dense.values)):
        assert same_bits(a, b)
    sparse.write(str(tmp_path / "b32.json"))
    dense.write(str(tmp_path / "dense32.json"))
    d32, dense32 = sl.read_field(str(tmp_path / "b32.json")).to_dense(), sl.read_field(str(tmp_path / "dense32.json"))
    for a, b in zip(grids(d32.values) + grids(d32.gradient), grids(dense32.values) + grids(dense32.gradient)):
        assert same_bits(a, b)
    with pytest.raises(RuntimeError, match="already exists"):
        sparse.write(path)


def test_band_without_gradient_has_the_same_distances_and_triangles(pair, tmp_path):
    """band=W, gradient=False: no gradient held (None), the same distances, triangles and points bit for bit,
    less memory; to_dense() without gradient; write() without the gradient channel or grid."""
    mesh, lattice, resolution, keywords, sparse, dense = pair
    slim = sl.sample(mesh, lattice, resolution, band=W, gradient=False, backend="cpu", threads=2, **keywords)
    assert slim.gradient is None and sparse.gradient is not None
    for name in ("distance", "triangle", "points", "indices", "subgrid"):
        assert same_bits(getattr(slim, name), getattr(sparse, name)), name
    assert slim.counts == sparse.counts and slim.nbytes < sparse.nbytes
    same_sdf = sl.SDF(mesh, backend="cpu", threads=2, **keywords).sample(lattice, resolution, band=W, gradient=False)
    assert same_sdf.gradient is None and same_bits(same_sdf.distance, sparse.distance)
    d = slim.to_dense()
    assert d.gradient is None
    for a, b in zip(grids(d.values) + grids(d.triangle), grids(dense.values) + grids(dense.triangle)):
        assert same_bits(a, b)
    path = str(tmp_path / "slim.json")
    files = slim.write(path, dtype="float64")
    assert len(files) == 7  # header, 6 channels: no gradient
    with open(path) as f:
        assert "gradient" not in json.load(f)["channels"]
    back = sl.read_field(path)
    assert back.gradient is None and same_bits(back.distance, sparse.distance) and same_bits(back.triangle, sparse.triangle)
    try:
        import pyopenvdb
    except ImportError:
        pyopenvdb = None
    if sl.build_info()["optional"]["openvdb"]["found"] and pyopenvdb is not None:
        vdb = str(tmp_path / "slim.vdb")
        assert slim.write(vdb) == [vdb]
        parts = [""] if slim.lattice == "cc" else ["_primary", "_secondary"]
        assert {g.name for g in pyopenvdb.readAll(vdb)[0]} == {"distance" + p for p in parts}
    with pytest.raises(TypeError, match="gradient= goes with band=W"):
        sl.sample(mesh, lattice, resolution, gradient=False, backend="cpu", **keywords)
    with pytest.raises(TypeError, match="True or False"):
        sl.sample(mesh, lattice, resolution, band=W, gradient="no", backend="cpu", **keywords)


def test_band_without_triangles_has_the_same_values_points_and_level_sets(pair, tmp_path):
    """band=W, closest_triangle=False (with and without gradient=False): no triangle held (None), the same
    distances, gradients, points and counts bit for bit, less memory; to_dense() without triangles but the
    same values; write() of .json holds the band points' mask, read back as the same band; the .nvdb is the
    full band's byte for byte and the .vdb holds the same active voxels and values."""
    mesh, lattice, resolution, keywords, sparse, dense = pair
    for gradient in (True, False):
        lean = sl.sample(mesh, lattice, resolution, band=W, gradient=gradient, closest_triangle=False, backend="cpu",
                         threads=2, **keywords)
        assert lean.triangle is None and (lean.gradient is None) == (not gradient)
        names = ("distance", "points", "indices", "subgrid") + (("gradient",) if gradient else ())
        for name in names:
            assert same_bits(getattr(lean, name), getattr(sparse, name)), name
        assert lean.counts == sparse.counts and lean.nbytes < sparse.nbytes
        d = lean.to_dense()
        assert d.triangle is None
        for a, b in zip(grids(d.values), grids(dense.values)):
            assert same_bits(a, b)
        if gradient:
            for a, b in zip(grids(d.gradient), grids(dense.gradient)):
                assert same_bits(a, b)
    same_sdf = sl.SDF(mesh, backend="cpu", threads=2, **keywords).sample(lattice, resolution, band=W, gradient=False,
                                                                          closest_triangle=False)
    assert same_sdf.triangle is None and same_bits(same_sdf.distance, sparse.distance)
    path = str(tmp_path / "lean.json")
    files = lean.write(path, dtype="float64")
    with open(path) as f:
        channels = json.load(f)["channels"]
    assert "closest_triangle" not in channels and channels["band_points"]["dtype"] == "uint64"
    assert len(files) == 7  # header, 6 channels: no gradient, the mask for the triangles
    back = sl.read_field(path)
    assert back.triangle is None and back.gradient is None and back.counts == sparse.counts
    assert same_bits(back.distance, sparse.distance) and same_bits(back.points, sparse.points)
    with pytest.raises(ValueError, match="holds no closest triangle"):
        lean.write(str(tmp_path / "t.vdb"), closest_triangle=True)
    try:
        sparse.write(str(tmp_path / "full.nvdb"))
    except RuntimeError as e:  # a build without NanoVDB
        assert "NanoVDB" in str(e)
    else:
        lean.write(str(tmp_path / "lean.nvdb"))
        assert (tmp_path / "full.nvdb").read_bytes() == (tmp_path / "lean.nvdb").read_bytes()
    try:
        import pyopenvdb
    except ImportError:
        pyopenvdb = None
    if sl.build_info()["optional"]["openvdb"]["found"] and pyopenvdb is not None:
        sparse.write(str(tmp_path / "full.vdb"))
        lean.write(str(tmp_path / "lean.vdb"))
        full_grids = {g.name: g for g in pyopenvdb.readAll(str(tmp_path / "full.vdb"))[0]}
        lean_grids = {g.name: g for g in pyopenvdb.readAll(str(tmp_path / "lean.vdb"))[0]}
        for name, grid in lean_grids.items():
            if not name.startswith("distance"):
                continue
            def on(g):
                return sorted((tuple(item["min"]), item["value"]) for item in g.citerOnValues())
            assert grid.activeVoxelCount() == full_grids[name].activeVoxelCount() > 0
            assert on(grid) == on(full_grids[name])
    with pytest.raises(TypeError, match="closest_triangle= goes with band=W"):
        sl.sample(mesh, lattice, resolution, closest_triangle=False, backend="cpu", **keywords)
    with pytest.raises(TypeError, match="True or False"):
        sl.sample(mesh, lattice, resolution, band=W, closest_triangle=0, backend="cpu", **keywords)


def test_reconstruct_inside_the_band_is_the_dense_fields(pair):
    _, lattice, *_, sparse, dense = pair
    interpolator = "tricubic_lm" if lattice == "cc" else "bcc_cubic"
    rng = np.random.default_rng(35)
    points = sparse.points[rng.choice(len(sparse), 400)] + rng.uniform(-0.4, 0.4, (400, 3)) * sparse.spacing
    values, gradients = sparse.reconstruct(points, interpolator, "true")
    dense_values, dense_gradients = dense.reconstruct(points, interpolator, "true")
    inside = ~np.isnan(values)
    assert 0 < inside.sum() < len(points)  # some near the band's edge are outside its cells
    assert same_bits(values[inside], dense_values[inside])
    assert same_bits(gradients[inside], dense_gradients[inside])
    clamped, _ = sparse.reconstruct(points, interpolator, "true", outside="clamp")
    dense_clamped, _ = dense.reconstruct(points, interpolator, "true", outside="clamp")
    assert same_bits(clamped, dense_clamped)  # the dense band field's reconstruction, from +-W off the band
    on_lattice = points[~np.isnan(dense_values)]  # off the lattice, the lattice's message comes first
    with pytest.raises(ValueError, match="outside the band's cells"):
        sparse.reconstruct(on_lattice, interpolator, "true", outside="error")
    far, _ = sparse.reconstruct(np.array([[1e3, 0.0, 0.0]]), interpolator, "true")
    assert np.isnan(far[0])  # outside the lattice, as the dense field


def test_reconstruct_is_the_dense_fields_for_each_filter_and_derivative_source(pair):
    _, lattice, *_, sparse, dense = pair
    filters = [("trilinear", "fd"), ("tricubic_lm", "fd"), ("catmull_rom", "fd"), ("cc_bspline3", "fd")] if lattice == "cc" else [
        ("bcc_linear", "fd"), ("bcc_cubic", "fd"), ("bcc_cubic", "fd_weighted"), ("bcc_box_quintic_qi", "fd"),
        ("bcc_box_quintic", "fd")]
    rng = np.random.default_rng(36)
    lo, hi = np.min(sparse.points, axis=0) - 2 * sparse.spacing, np.max(sparse.points, axis=0) + 2 * sparse.spacing
    points = np.concatenate([sparse.points[rng.choice(len(sparse), 300)] + rng.uniform(-1.5, 1.5, (300, 3)) * sparse.spacing,
                             rng.uniform(lo, hi, (200, 3))])
    for interpolator, derivatives in filters:
        for outside in ("nan", "clamp"):
            values, gradients = sparse.reconstruct(points, interpolator, derivatives, outside=outside)
            dense_values, dense_gradients = dense.reconstruct(points, interpolator, derivatives, outside=outside)
            kept = ~np.isnan(values)
            assert kept.sum() > 0, interpolator
            assert same_bits(values[kept], dense_values[kept]), (interpolator, derivatives, outside)
            assert same_bits(gradients[kept], dense_gradients[kept]), (interpolator, derivatives, outside)
            if outside == "clamp":
                assert kept.all() and same_bits(values, dense_values)
    with pytest.raises(ValueError, match="outside the field's domain"):  # the lattice's edge first, as the dense field
        sparse.reconstruct(np.array([[1e3, 0.0, 0.0]]), filters[0][0], outside="error")


def test_reconstruct_needs_no_dense_field(pair, monkeypatch, tmp_path):
    _, lattice, *_, sparse, dense = pair
    interpolator = "tricubic_lm" if lattice == "cc" else "bcc_cubic"
    points = sparse.points[:200] + 0.1 * sparse.spacing
    want, want_gradients = dense.reconstruct(points, interpolator, "true")
    sparse.write(str(tmp_path / "band.json"), dtype="float64")
    band = sl.read_field(str(tmp_path / "band.json"))  # a fresh SparseField: nothing densified
    monkeypatch.setenv("SDF_MEMORY_AVAILABLE", "1000")  # below the dense field's size
    got, gradients = band.reconstruct(points, interpolator, "true")
    kept = ~np.isnan(got)
    assert kept.sum() > 0 and same_bits(got[kept], want[kept]) and same_bits(gradients[kept], want_gradients[kept])
    with pytest.raises(RuntimeError, match="densifying"):
        band.to_dense()
    spline = "cc_bspline3" if lattice == "cc" else "bcc_box_quintic"  # its prefilter spans the lattice: densified
    with pytest.raises(RuntimeError, match="densifying"):
        band.reconstruct(points, spline)


def test_hostile_sparse_field_files_are_refused_naming_the_file(pair, tmp_path):
    *_, sparse, _ = pair
    path = tmp_path / "band.json"
    sparse.write(str(path))
    distance = tmp_path / "band.distance.raw"
    distance.write_bytes(distance.read_bytes()[:-4])
    with pytest.raises(RuntimeError, match=r"band\.json.*channel 'distance'.*holds"):
        sl.read_field(str(path))
    header = json.loads(path.read_text())
    header["band"]["active_blocks"] = 10**12  # past the lattice's blocks: refused before anything is allocated
    path.write_text(json.dumps(header))
    with pytest.raises(ValueError, match=r"band\.json: key 'band\.active_blocks': expected 0 to"):
        sl.read_field(str(path))


def test_a_float32_files_band_width_must_be_a_float32(pair, tmp_path):
    """A float32 file's +-W are float32 values: a header whose width rounds to 0 or overflows
    float32 is refused before anything is read (densified it would hold +-0 or +-inf)."""
    *_, sparse, _ = pair
    path = tmp_path / "band.json"
    sparse.write(str(path))  # dtype float32
    header = json.loads(path.read_text())
    for width in (1e-50, 1e300):
        header["band"]["width"] = width
        path.write_text(json.dumps(header))
        with pytest.raises(ValueError, match=r"band\.json: key 'band\.width': .* cannot be stored in float32"):
            sl.read_field(str(path))


def test_level_sets_refuse_float64(pair, tmp_path):
    """.vdb and .nvdb store float32: dtype="float64" is refused, not silently narrowed."""
    *_, sparse, _ = pair
    for name in ("band.vdb", "band.nvdb"):
        with pytest.raises(ValueError, match=r"stores float32"):
            sparse.write(str(tmp_path / name), dtype="float64")
        assert not (tmp_path / name).exists()


def test_a_band_may_have_a_lattice_no_dense_field_may():
    """8192^3 (2^39 points) is beyond a dense field's limit (2^36) but within a sparse band's
    (2^42): the band of a box spanning a hundred of its spacings, its points holding the point
    query's values at their positions, bit for bit."""
    mesh = sl.Mesh(*box_arrays(), name="box")
    with pytest.raises(ValueError, match=r"densely.*a sparse narrow band may have up to 2\^42"):
        sl.sample(mesh, resolution=8192, margin=40.0, backend="cpu")
    sparse = sl.sample(mesh, resolution=8192, margin=40.0, band=0.02, backend="cpu", threads=2, precision="float")
    assert sparse.resolution == (8192, 8192, 8192) and sparse.num_points == 8192 ** 3
    assert sparse.counts["blocks"] == 1024 ** 3 and len(sparse) > 10000
    exact = sl.query(mesh, sparse.points, backend="cpu", threads=2, precision="float")
    assert same_bits(sparse.distance, exact.distance)
    assert same_bits(sparse.triangle, exact.triangle)
