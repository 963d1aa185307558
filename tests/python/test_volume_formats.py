"""Volume formats (harness/io/volume_formats.h) read back by independent readers: a sampling run
writes a CC and a BCC field with "output": {"formats": [...]}, and every .vdb (pyopenvdb), .vti
(VTK's own XML reader), .npy and .npz (NumPy) is compared with the project's field file, read
here with NumPy from its JSON header and raw channels (docs/field-format.md).

CTest's volume_formats runs this file with RUN_EXPERIMENT set to the built run-experiment and
SDF_HAVE_OPENVDB to 1 or 0 (tests/python/CMakeLists.txt); without them it is skipped."""
import glob
import json
import os
import subprocess

import numpy as np
import pytest

BAND = 2.0  # the OpenVDB band's half-width in spacings


def _run_experiment(tmp, config):
    exe = os.environ.get("RUN_EXPERIMENT")
    if not exe:
        pytest.skip("RUN_EXPERIMENT (the run-experiment binary) is not set: CTest's volume_formats sets it")
    path = tmp / (config["name"] + ".json")
    path.write_text(json.dumps(config))
    env = dict(os.environ, SDF_CACHE_DIR=str(tmp / "cache"))
    return subprocess.run([exe, str(path), "--output-root", str(tmp / "results"), "--quiet"], capture_output=True,
                          text=True, env=env)


def _import(module, package):
    """An independent reader, or a failure naming its Debian package (scripts/install-deps)."""
    try:
        return __import__(module)
    except ImportError as e:
        pytest.fail("%s (install the Debian package %s: scripts/install-deps)" % (e, package))


def _have_openvdb():
    return os.environ.get("SDF_HAVE_OPENVDB", "0") == "1"


def _config(name, dtype, formats):
    return {"name": name, "kind": "sampling", "description": "volume formats round trip",
            "mesh": {"shape": "sphere", "subdivisions": 2},
            "lattices": [{"type": "cc", "resolution": [9, 8, 7]}, {"type": "bcc", "resolution": [7, 6, 10]}],
            "sampler": {"backend": "cpu", "threads": 1, "progress": False},
            "output": {"dtype": dtype, "formats": formats, "vdb_band": BAND}}


class Field:
    """A field file read with NumPy alone: its grids as (part, origin, spacing, distance[z,y,x],
    gradient[z,y,x,3]); part is "" for CC, "primary" / "secondary" for BCC."""

    def __init__(self, header_path):
        with open(header_path) as f:
            self.header = json.load(f)
        lattice = self.header["lattice"]
        self.type, self.spacing = lattice["type"], lattice["spacing"]
        origin = np.array(lattice["origin"])
        nx, ny, nz = lattice["resolution"]
        if self.type == "cc":
            shapes = [("", origin, (nz, ny, nx))]
        else:
            half = 0.5 * self.spacing
            shapes = [("primary", origin, (nz // 2, ny, nx)), ("secondary", origin + half, (nz // 2 - 1, ny - 1, nx - 1))]
        distance = self._channel(header_path, "distance", 1)
        gradient = self._channel(header_path, "gradient", 3)
        self.grids, first = [], 0
        for part, grid_origin, shape in shapes:
            count = int(np.prod(shape))
            self.grids.append((part, grid_origin, distance[first:first + count].reshape(shape),
                               gradient[first:first + count].reshape(shape + (3,))))
            first += count
        assert first == len(distance), "the sub-grids cover every point"

    def _channel(self, header_path, name, components):
        channel = self.header["channels"][name]
        data = np.fromfile(os.path.join(os.path.dirname(header_path), channel["file"]), dtype="<" + {
            "float32": "f4", "float64": "f8"}[channel["dtype"]])
        return data.reshape(-1, components) if components > 1 else data


@pytest.fixture(scope="module", params=["float32", "float64"])
def run(request, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("volumes_" + request.param)
    formats = ["vti", "npy", "npz"] + (["vdb"] if _have_openvdb() else [])
    r = _run_experiment(tmp, _config("volumes", request.param, formats))
    assert r.returncode == 0, r.stdout + r.stderr
    headers = sorted(glob.glob(str(tmp / "results" / "volumes" / "*" / "fields" / "*.json")))
    assert [os.path.basename(h) for h in headers] == ["sphere-bcc-7x6x10.json", "sphere-cc-9x8x7.json"]
    return request.param, [(h[:-len(".json")], Field(h)) for h in headers]


def _numpy_dtype(dtype):
    return np.float32 if dtype == "float32" else np.float64


def test_npy_holds_every_grid_and_gradient(run):
    dtype, fields = run
    for stem, field in fields:
        for part, _, distance, gradient in field.grids:
            name = stem + ("." + part if part else "")
            d, g = np.load(name + ".npy"), np.load(name + ".gradient.npy")
            assert d.dtype == _numpy_dtype(dtype) and d.shape == distance.shape
            assert g.shape == distance.shape + (3,)
            np.testing.assert_array_equal(d, distance)
            np.testing.assert_array_equal(g, gradient)


def test_npz_holds_arrays_origin_spacing_and_lattice(run):
    _, fields = run
    for stem, field in fields:
        with np.load(stem + ".npz") as z:
            assert str(z["lattice"]) == field.type
            assert float(z["spacing"]) == field.spacing
            for part, origin, distance, gradient in field.grids:
                suffix = "_" + part if part else ""
                np.testing.assert_array_equal(z["distance" + suffix], distance)
                np.testing.assert_array_equal(z["gradient" + suffix], gradient)
                np.testing.assert_array_equal(z["origin" + suffix], origin)
    bcc_stem, bcc = fields[0]
    assert bcc.type == "bcc"
    with np.load(bcc_stem + ".npz") as z:  # the secondary grid sits h/2 from the primary on every axis
        np.testing.assert_allclose(z["origin_secondary"] - z["origin_primary"], [bcc.spacing / 2] * 3, rtol=0, atol=1e-15)


def _read_vti(path):
    vtk = _import("vtk", "python3-vtk9")
    from vtk.util.numpy_support import vtk_to_numpy
    reader = vtk.vtkXMLImageDataReader()
    reader.SetFileName(path)
    reader.Update()
    image = reader.GetOutput()
    nx, ny, nz = image.GetDimensions()
    points = image.GetPointData()
    assert points.GetScalars().GetName() == "distance" and points.GetVectors().GetName() == "gradient"
    distance = vtk_to_numpy(points.GetArray("distance")).reshape(nz, ny, nx)
    gradient = vtk_to_numpy(points.GetArray("gradient")).reshape(nz, ny, nx, 3)
    return np.array(image.GetOrigin()), np.array(image.GetSpacing()), distance, gradient


def test_vti_read_by_vtk_has_origin_spacing_and_point_data(run):
    dtype, fields = run
    for stem, field in fields:
        for part, origin, distance, gradient in field.grids:
            got_origin, spacing, d, g = _read_vti(stem + ("." + part if part else "") + ".vti")
            np.testing.assert_array_equal(got_origin, origin)
            np.testing.assert_array_equal(spacing, [field.spacing] * 3)
            assert d.dtype == _numpy_dtype(dtype)
            np.testing.assert_array_equal(d, distance)
            np.testing.assert_array_equal(g, gradient)


def _read_vdb(path):
    pyopenvdb = _import("pyopenvdb", "python3-openvdb")
    grids, _ = pyopenvdb.readAll(path)
    return {grid.name: grid for grid in grids}


def test_vdb_read_by_pyopenvdb_is_a_narrow_band_level_set_with_the_lattice_transform(run):
    if not _have_openvdb():
        pytest.skip("this build has no OpenVDB (test_vdb_without_openvdb_is_refused_naming_it checks the error)")
    _, fields = run
    for stem, field in fields:
        grids = _read_vdb(stem + ".vdb")
        expected_names = {n + ("_" + p if p else "") for p, *_ in field.grids for n in ("distance", "gradient")}
        assert set(grids) == expected_names
        band = np.float32(BAND * field.spacing)
        for part, origin, distance, gradient in field.grids:
            suffix = "_" + part if part else ""
            level_set, normals = grids["distance" + suffix], grids["gradient" + suffix]
            assert str(level_set.gridClass) == "level set"
            assert level_set.background == pytest.approx(band, rel=1e-7)
            for grid in (level_set, normals):
                np.testing.assert_allclose(grid.transform.indexToWorld((0, 0, 0)), origin, rtol=0, atol=1e-12)
                np.testing.assert_allclose(grid.transform.indexToWorld((1, 1, 1)) - np.array(origin),
                                           [field.spacing] * 3, rtol=0, atol=1e-12)
            d_acc, n_acc = level_set.getConstAccessor(), normals.getConstAccessor()
            nz, ny, nx = distance.shape
            in_band = 0
            for k in range(nz):
                for j in range(ny):
                    for i in range(nx):
                        d = np.float32(distance[k, j, i])
                        value, active = d_acc.probeValue((i, j, k))
                        if abs(d) < band:
                            in_band += 1
                            assert active and value == d, (part, i, j, k)
                            n, n_active = n_acc.probeValue((i, j, k))
                            assert n_active
                            np.testing.assert_array_equal(np.float32(n), gradient[k, j, i].astype(np.float32))
                        else:  # outside the band: the background, signed by the side
                            assert not active and value == np.copysign(band, d), (part, i, j, k, value, d)
            assert in_band == level_set.activeVoxelCount() == normals.activeVoxelCount() > 0


def test_vdb_without_openvdb_is_refused_naming_it(tmp_path):
    if _have_openvdb():
        pytest.skip("this build has OpenVDB")
    r = _run_experiment(tmp_path, _config("no_vdb", "float32", ["vdb"]))
    assert r.returncode != 0 and "output.formats" in r.stderr and "OpenVDB" in r.stderr, r.stderr


def test_unknown_and_repeated_formats_are_refused_naming_the_key(tmp_path):
    r = _run_experiment(tmp_path, _config("bad", "float32", ["vtk"]))
    assert r.returncode != 0 and "output.formats" in r.stderr and "vdb, vti, npy, npz" in r.stderr, r.stderr
    r = _run_experiment(tmp_path, _config("twice", "float32", ["npy", "npy"]))
    assert r.returncode != 0 and "listed twice" in r.stderr, r.stderr
