"""sdf-sample --band W --sparse --vdb (harness/io/sparse_vdb_file.h) read back by Debian's pyopenvdb
and compared with the dense banded field of an independent run (sdf-sample --band W, no --sparse),
read here with NumPy from its field file (docs/field-format.md): a level set of background W whose
active voxels are exactly the band's points holding float32 of their exact distances, with the
dense field's sign at 10,000 random lattice points and its +-W at every point outside the band.

CTest's sparse_vdb runs this file with SDF_SAMPLE set to the built sdf-sample and SDF_HAVE_OPENVDB
to 1 or 0 (tests/python/CMakeLists.txt); without them it is skipped."""
import json
import os
import subprocess

import numpy as np
import pytest

# An open box (its top face missing): under the winding sign, blocks far from the surface see its
# sides differ across the hole (the sparse band's mixed blocks).
OPEN_BOX = """v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
f 1 3 2
f 1 4 3
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
"""

CASES = [  # (name, mesh, lattice, resolution, band in mesh units, extra flags)
    ("sphere_cc", "shape:sphere", "cc", ["41", "37", "45"], 0.12, []),
    ("sphere_bcc", "shape:sphere", "bcc", ["40"], 0.08, []),
    ("torus_cc", "shape:torus", "cc", ["36"], 0.1, []),
    ("open_box_winding_cc", "open_box.obj", "cc", ["40"], 0.05, ["--sign", "winding"]),
    ("open_box_winding_bcc", "open_box.obj", "bcc", ["20"], 0.05, ["--sign", "winding"]),
]


def _sdf_sample(tmp, mesh, args):
    exe = os.environ.get("SDF_SAMPLE")
    if not exe:
        pytest.skip("SDF_SAMPLE (the sdf-sample binary) is not set: CTest's sparse_vdb sets it")
    r = subprocess.run([exe, mesh] + args + ["--backend", "cpu", "--threads", "2", "--quiet"], capture_output=True,
                       text=True, cwd=str(tmp))
    assert r.returncode == 0, r.stdout + r.stderr
    return r.stdout


def _channel(header_path, header, name):
    channel = header["channels"][name]
    dtype = {"float32": "<f4", "float64": "<f8", "int32": "<i4"}[channel["dtype"]]
    data = np.fromfile(os.path.join(os.path.dirname(header_path), channel["file"]), dtype=dtype)
    return data.reshape(-1, 3) if name == "gradient" else data


def _dense_grids(header_path):
    """The dense field's CC grids: (part, origin, spacing, distance, gradient, triangle), arrays [z, y, x]."""
    with open(header_path) as f:
        header = json.load(f)
    lattice = header["lattice"]
    h, origin = lattice["spacing"], np.array(lattice["origin"])
    nx, ny, nz = lattice["resolution"]
    if lattice["type"] == "cc":
        shapes = [("", origin, (nz, ny, nx))]
    else:
        shapes = [("primary", origin, (nz // 2, ny, nx)), ("secondary", origin + h / 2, (nz // 2 - 1, ny - 1, nx - 1))]
    d, g, t = (_channel(header_path, header, n) for n in ("distance", "gradient", "closest_triangle"))
    grids, first = [], 0
    for part, o, shape in shapes:
        n = int(np.prod(shape))
        grids.append((part, o, h, d[first:first + n].reshape(shape), g[first:first + n].reshape(shape + (3,)),
                      t[first:first + n].reshape(shape)))
        first += n
    assert first == len(d)
    return grids


def _active_voxels(grid):
    """{(i, j, k): value} of the grid's active voxels; fails on an active tile."""
    out = {}
    for item in grid.citerOnValues():
        assert item["depth"] == grid.treeDepth - 1, "no active tiles: %r" % (item,)
        out[tuple(item["min"])] = item["value"]
    return out


@pytest.fixture(scope="module", params=CASES, ids=[c[0] for c in CASES])
def case(request, tmp_path_factory):
    if os.environ.get("SDF_HAVE_OPENVDB", "0") != "1":
        pytest.skip("this build has no OpenVDB")
    name, mesh, lattice, resolution, band, flags = request.param
    tmp = tmp_path_factory.mktemp(name)
    (tmp / "open_box.obj").write_text(OPEN_BOX)
    common = [mesh, "--lattice", lattice, "--resolution"] + resolution + ["--band", repr(band), "--dtype", "float64"] + flags
    _sdf_sample(tmp, common[0], common[1:] + ["--out", "dense.json"])
    stdout = _sdf_sample(tmp, common[0], common[1:] + ["--sparse", "--out", "sparse.json", "--vdb", "band.vdb"])
    try:
        import pyopenvdb
    except ImportError as e:
        pytest.fail("%s (install the Debian package python3-openvdb: scripts/install-deps)" % e)
    grids, _ = pyopenvdb.readAll(str(tmp / "band.vdb"))
    return band, _dense_grids(str(tmp / "dense.json")), {g.name: g for g in grids}, stdout


def test_level_set_grids_named_with_background_and_transform(case):
    band, dense, grids, _ = case
    assert set(grids) == {n + ("_" + p if p else "") for p, *_ in dense for n in ("distance", "gradient")}
    for part, origin, h, *_ in dense:
        suffix = "_" + part if part else ""
        level_set = grids["distance" + suffix]
        assert str(level_set.gridClass) == "level set"
        assert level_set.background == np.float32(band)
        for grid in (level_set, grids["gradient" + suffix]):
            np.testing.assert_allclose(grid.transform.indexToWorld((0, 0, 0)), origin, rtol=0, atol=1e-12)
            np.testing.assert_allclose(grid.transform.indexToWorld((1, 1, 1)) - origin, [h] * 3, rtol=0, atol=1e-12)


def test_active_voxels_are_the_band_points_with_their_exact_values(case):
    _, dense, grids, _ = case
    total = 0
    for part, _, _, distance, gradient, triangle in dense:
        suffix = "_" + part if part else ""
        in_band = np.argwhere(triangle != -2)  # (k, j, i): the dense field's band points
        expected = {(int(i), int(j), int(k)) for k, j, i in in_band}
        active = _active_voxels(grids["distance" + suffix])
        assert set(active) == expected
        for (i, j, k), value in active.items():
            assert np.float32(value) == np.float32(distance[k, j, i]), (part, i, j, k)
        normals = _active_voxels(grids["gradient" + suffix])
        assert set(normals) == expected
        for (i, j, k), n in normals.items():
            np.testing.assert_array_equal(np.float32(n), gradient[k, j, i].astype(np.float32))
        total += len(expected)
    assert total > 0


def test_sign_at_random_lattice_points_is_the_dense_fields(case):
    _, dense, grids, _ = case
    rng = np.random.default_rng(35)
    for part, _, _, distance, *_ in dense:
        acc = grids["distance" + ("_" + part if part else "")].getConstAccessor()
        nz, ny, nx = distance.shape
        for k, j, i in zip(rng.integers(0, nz, 10000), rng.integers(0, ny, 10000), rng.integers(0, nx, 10000)):
            value = acc.getValue((int(i), int(j), int(k)))
            assert (value < 0) == (distance[k, j, i] < 0), (part, i, j, k, value, distance[k, j, i])


def test_every_lattice_point_reads_the_dense_fields_float32_value(case):
    """Inside the band the exact value, outside it +-W with its side: inside tiles, mixed blocks."""
    _, dense, grids, _ = case
    for part, _, _, distance, *_ in dense:
        grid = grids["distance" + ("_" + part if part else "")]
        nz, ny, nx = distance.shape
        values = np.zeros((nx, ny, nz), dtype=np.float32)  # copyToArray is indexed [x, y, z]
        grid.copyToArray(values, ijk=(0, 0, 0))
        np.testing.assert_array_equal(values, distance.astype(np.float32).transpose(2, 1, 0))


def test_the_spheres_have_inside_tiles(case, request):
    """So that the value test above reads -W tiles (the sampler's report counts them)."""
    _, _, _, stdout = case
    if "sphere" not in request.node.callspec.id:
        pytest.skip("the torus's tube and the open box's inside are thin")
    assert int(stdout.split(" tiles (")[1].split(" inside")[0]) > 0


def test_the_open_box_under_the_winding_sign_has_mixed_blocks(case, request):
    """So that the value test above reads mixed leaves (per-point sides outside the band)."""
    _, _, _, stdout = case
    if "open_box" not in request.node.callspec.id:
        pytest.skip("closed meshes have no mixed blocks")
    assert int(stdout.split(" mixed;")[0].rsplit(" ", 1)[1]) > 0


def test_channels_without_gradient_keep_none_and_the_same_bytes(tmp_path):
    """--channels distance,closest_triangle --band W --sparse: the band is sampled without its gradient
    (the sampler's report says so), the dense and the sparse field files and the .vdb have no gradient,
    and their distances and triangles are the full run's bytes."""
    if os.environ.get("SDF_HAVE_OPENVDB", "0") != "1":
        pytest.skip("this build has no OpenVDB")
    import pyopenvdb
    common = ["--lattice", "cc", "--resolution", "36", "--band", "0.1", "--dtype", "float64", "--sparse"]
    slim_channels = ["--channels", "distance,closest_triangle"]
    _sdf_sample(tmp_path, "shape:torus", common + ["--out", "full.json", "--vdb", "full.vdb"])
    _sdf_sample(tmp_path, "shape:torus", common + slim_channels + ["--out", "slim.json", "--vdb", "slim.vdb"])
    _sdf_sample(tmp_path, "shape:torus", common + slim_channels + ["--layout", "sparse", "--out", "slim-sparse.json"])
    headers = {}
    for name in ("full", "slim", "slim-sparse"):
        with open(tmp_path / (name + ".json")) as f:
            headers[name] = json.load(f)
    assert "gradient" in headers["full"]["channels"]
    for name in ("slim", "slim-sparse"):
        assert "gradient" not in headers[name]["channels"] and "gradient_channel" not in headers[name]
        assert headers[name]["sampler"]["sparse_band"]["channels"] == ["distance", "closest_triangle"]
    for channel in ("distance", "closest_triangle"):
        full = _channel(str(tmp_path / "full.json"), headers["full"], channel)
        slim = _channel(str(tmp_path / "slim.json"), headers["slim"], channel)
        assert full.tobytes() == slim.tobytes(), channel
    assert {g.name for g in pyopenvdb.readAll(str(tmp_path / "full.vdb"))[0]} == {"distance", "gradient"}
    slim_grids = {g.name: g for g in pyopenvdb.readAll(str(tmp_path / "slim.vdb"))[0]}
    full_grids = {g.name: g for g in pyopenvdb.readAll(str(tmp_path / "full.vdb"))[0]}
    assert set(slim_grids) == {"distance"}
    assert slim_grids["distance"].activeVoxelCount() == full_grids["distance"].activeVoxelCount() > 0


def test_channels_distance_alone_keeps_neither_gradient_nor_triangles(tmp_path):
    """--channels distance --band W --sparse: the band holds the distance and its points' mask only (the
    sampler's report says so); the dense field file's distances are the full run's bytes, the sparse field
    file marks the band's points with its band_points mask, and the .vdb has the full run's active voxels
    and values."""
    if os.environ.get("SDF_HAVE_OPENVDB", "0") != "1":
        pytest.skip("this build has no OpenVDB")
    import pyopenvdb
    common = ["--lattice", "bcc", "--resolution", "30", "--band", "0.1", "--dtype", "float64", "--sparse"]
    lean = ["--channels", "distance"]
    _sdf_sample(tmp_path, "shape:torus", common + ["--out", "full.json", "--vdb", "full.vdb"])
    _sdf_sample(tmp_path, "shape:torus", common + lean + ["--out", "lean.json", "--vdb", "lean.vdb"])
    _sdf_sample(tmp_path, "shape:torus", common + lean + ["--layout", "sparse", "--out", "lean-sparse.json"])
    headers = {}
    for name in ("full", "lean", "lean-sparse"):
        with open(tmp_path / (name + ".json")) as f:
            headers[name] = json.load(f)
    for name in ("lean", "lean-sparse"):
        assert headers[name]["sampler"]["sparse_band"]["channels"] == ["distance"]
        assert "closest_triangle" not in headers[name]["channels"] and "gradient" not in headers[name]["channels"]
    assert headers["lean-sparse"]["channels"]["band_points"]["dtype"] == "uint64"
    assert headers["lean-sparse"]["band"]["band_points"] == headers["full"]["sampler"]["band"]["points_in_band"]
    full = _channel(str(tmp_path / "full.json"), headers["full"], "distance")
    assert full.tobytes() == _channel(str(tmp_path / "lean.json"), headers["lean"], "distance").tobytes()
    full_grids = {g.name: g for g in pyopenvdb.readAll(str(tmp_path / "full.vdb"))[0]}
    lean_grids = {g.name: g for g in pyopenvdb.readAll(str(tmp_path / "lean.vdb"))[0]}
    assert set(lean_grids) == {"distance_primary", "distance_secondary"}
    for name, grid in lean_grids.items():
        assert _active_voxels(grid) == _active_voxels(full_grids[name]) != {}
