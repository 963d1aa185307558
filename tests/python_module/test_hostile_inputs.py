"""Hostile inputs to the Python surfaces (issue 26): every bad argument or file gets an error
that names the argument (or the file) and what was expected, never a crash, a pybind11
"Unable to cast", or a Field of wrong numbers returned as a success.
"""
import json
import os
import zipfile

import numpy as np
import pytest

import sdf_lattices as sl
from sdf_lattices import data

NAN, INF = float("nan"), float("inf")
TETRA_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
TETRA_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


@pytest.fixture(scope="module")
def tetra():
    return sl.Mesh(TETRA_V, TETRA_F, name="tetra")


@pytest.fixture(scope="module")
def tetra_sdf(tetra):
    return sl.SDF(tetra, backend="cpu")


# ---- meshes from arrays ---------------------------------------------------------------------

@pytest.mark.parametrize("dtype", [complex, str, object, bool])
def test_vertices_of_a_non_real_dtype_are_refused(dtype):
    with pytest.raises(TypeError, match=r"vertices: expected an array of real numbers of shape \(N, 3\), got dtype"):
        sl.SDF((TETRA_V.astype(dtype), TETRA_F))


# ---- sample()'s lattice arguments -----------------------------------------------------------

@pytest.mark.parametrize("key, value", [("margin", "abc"), ("spacing", "x"), ("margin", 1j), ("spacing", [0.1])])
def test_number_arguments_of_the_wrong_type_are_named(tetra_sdf, key, value):
    kwargs = {key: value} if key == "spacing" else {key: value, "resolution": 4}
    with pytest.raises(TypeError, match=f"^{key}: expected a number, got "):
        tetra_sdf.sample(**kwargs)


@pytest.mark.parametrize("margin", [INF, NAN, -0.5])
def test_margins_that_are_not_finite_and_non_negative_are_refused(tetra_sdf, margin):
    with pytest.raises(ValueError, match="margin: expected a finite, non-negative fraction"):
        tetra_sdf.sample(resolution=4, margin=margin)


def test_subnormal_spacing_is_refused_and_large_counts_name_the_spacing(tetra_sdf):
    with pytest.raises(ValueError, match="spacing: expected a finite distance > 0 \\(and not subnormal\\), got 1e-320"):
        tetra_sdf.sample(spacing=1e-320, origin=(0, 0, 0), resolution=4)
    with pytest.raises(ValueError, match=r"spacing: 1e-300 gives more than 2\^30 points along an axis"):
        tetra_sdf.sample(bounds=((0, 0, 0), (1e300, 1, 1)), spacing=1e-300)


# ---- Field from arrays ----------------------------------------------------------------------

GRID = np.arange(64.0).reshape(4, 4, 4)


@pytest.mark.parametrize("values", [np.full((4, 4, 4), "1"), np.zeros((4, 4, 4), complex), np.zeros((4, 4, 4), object),
                                    np.zeros((4, 4, 4), bool)])
def test_field_values_of_a_non_real_dtype_are_refused(values):
    with pytest.raises(TypeError, match="values: expected an array of real numbers"):
        sl.Field(values, (0, 0, 0), 1.0)


@pytest.mark.parametrize("origin", [(NAN, 0, 0), (0, INF, 0), ("a", 0, 0)])
def test_field_origins_that_are_not_finite_numbers_are_refused(origin):
    with pytest.raises((ValueError, TypeError), match="origin: expected 3"):
        sl.Field(GRID, origin, 1.0)


@pytest.mark.parametrize("spacing", [NAN, INF, 0.0, -1.0, 1e-320])
def test_field_spacings_that_are_not_positive_normal_numbers_are_refused(spacing):
    with pytest.raises(ValueError, match="spacing: expected a finite distance > 0"):
        sl.Field(GRID, (0, 0, 0), spacing)


def test_a_field_whose_far_corner_overflows_is_refused():
    with pytest.raises(ValueError, match="the lattice's far corner .* is not finite"):
        sl.Field(GRID, (1.7e308, 0, 0), 1e308)


def test_field_triangles_must_be_integer_indices():
    with pytest.raises(TypeError, match="triangle: expected integer arrays"):
        sl.Field(GRID, (0, 0, 0), 1.0, triangle=np.zeros((4, 4, 4)) + 0.5)
    with pytest.raises(ValueError, match="triangle: entry 0 is -7; expected a triangle index >= 0, or -2"):
        sl.Field(GRID, (0, 0, 0), 1.0, triangle=np.full((4, 4, 4), -7))
    f = sl.Field(GRID, (0, 0, 0), 1.0, triangle=np.full((4, 4, 4), -2, np.int64))
    assert f.triangle.min() == -2


def test_field_gradients_of_a_non_real_dtype_are_refused():
    with pytest.raises(TypeError, match="gradient: expected an array of real numbers"):
        sl.Field(GRID, (0, 0, 0), 1.0, gradient=np.zeros((4, 4, 4, 3), complex))


@pytest.mark.parametrize("sigma2", [NAN, -1.0, 0.0, INF])
def test_reconstruct_refuses_variances_that_are_not_positive(sigma2):
    f = sl.Field(GRID, (0, 0, 0), 1.0)
    with pytest.raises(ValueError, match="sigma2: expected a finite variance > 0"):
        f.reconstruct(np.ones((1, 3)), sigma2=sigma2)


# ---- read_field of truncated or lying files --------------------------------------------------

@pytest.fixture()
def written(tmp_path):
    f = sl.Field(GRID, (0, 0, 0), 1.0)
    for ext in ("npz", "json", "vti"):
        f.write(str(tmp_path / f"ok.{ext}"))
    return tmp_path


def corrupt(path, how):
    b = path.read_bytes()
    if how == "empty":
        b = b""
    elif how == "cut":
        b = b[:len(b) // 2]
    elif how == "flipped":
        b = bytearray(b)
        for i in range(len(b) // 3, len(b) // 3 + 8):
            b[i] ^= 0x55
        b = bytes(b)
    out = path.with_name(f"{how}{path.suffix}")
    out.write_bytes(b)
    return str(out)


@pytest.mark.parametrize("how", ["empty", "cut", "flipped"])
def test_a_damaged_npz_is_named(written, how):
    bad = corrupt(written / "ok.npz", how)
    with pytest.raises(ValueError, match="^" + bad.replace(".", r"\.") + ": "):
        sl.read_field(bad)


def test_an_npz_with_misshapen_entries_is_named(tmp_path):
    path = str(tmp_path / "lie.npz")
    np.savez(path, lattice="cc", distance=GRID, origin=np.float64(0), spacing=np.ones(3))
    with pytest.raises(ValueError, match="^" + path.replace(".", r"\.") + ": "):
        sl.read_field(path)
    np.savez(path, lattice="cc", distance=GRID, origin=np.zeros(3), spacing=np.float64(1e-320))
    with pytest.raises(ValueError, match=r"lie\.npz: spacing: expected a finite distance > 0"):
        sl.read_field(path)
    np.savez(path, lattice="cc", origin=np.zeros(3), spacing=np.float64(1))
    with pytest.raises(ValueError, match=r"lie\.npz: .*distance"):
        sl.read_field(path)


@pytest.mark.parametrize("how", ["empty", "cut", "flipped"])
def test_a_damaged_vti_is_named_as_unreadable(written, how):
    pytest.importorskip("vtk")
    bad = corrupt(written / "ok.vti", how)
    with pytest.raises(ValueError, match="^" + bad.replace(".", r"\.") + ": not a readable VTK ImageData XML file"):
        sl.read_field(bad)


@pytest.mark.parametrize("key, value, message", [
    ("spacing", 1e-320, "key 'lattice.spacing'"),
    ("origin", [1.7e308, 0, 0], "not finite"),
])
def test_field_headers_with_spacings_or_corners_no_double_can_hold_are_refused(written, key, value, message):
    header = json.loads((written / "ok.json").read_text())
    header["lattice"][key] = value
    (written / "lie.json").write_text(json.dumps(header))
    if key == "origin":
        header["lattice"]["spacing"] = 1e308
        (written / "lie.json").write_text(json.dumps(header))
    with pytest.raises(ValueError, match=message):
        sl.read_field(str(written / "lie.json"))


# ---- sdf_lattices.data ----------------------------------------------------------------------

@pytest.mark.parametrize("sigmas, message", [
    (0.1, "sigmas: expected a sequence of standard deviations"),
    ("0.1", "sigmas: expected a sequence of standard deviations"),
    (("a",), "sigmas: expected numbers, got 'a'"),
    ((None,), "sigmas: expected numbers, got None"),
    ((NAN,), "sigmas: expected finite values > 0, got nan"),
    ((-0.1,), "sigmas: expected finite values > 0"),
])
def test_near_surface_sigmas_are_checked_by_name(tetra, sigmas, message):
    with pytest.raises(ValueError, match=message):
        data.sample_near_surface(tetra, 10, sigmas=sigmas)


@pytest.mark.parametrize("count", [-1, 1.5, True, 10**15])
def test_near_surface_counts_are_checked_before_any_array_is_made(tetra, count):
    with pytest.raises(ValueError, match="count: expected"):
        data.sample_near_surface(tetra, count)
