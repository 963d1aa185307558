"""Issue 38, items 3-5 and 7: results that stay true after the call, the caller's numbering,
a .vti cut inside its gradient refused, the winding number said for what it is (fast with
its bound, or exact against a direct NumPy sum of Van Oosterom-Strackee solid angles), and
messages that name the problem (MemoryError with the size, warnings at the caller's line,
unsigned face indices, one name for one bad row)."""
import inspect
import os
import re
import warnings

import numpy as np
import pytest

import sdf_lattices as sl

BOX_V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
BOX_F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])


def here():
    return inspect.currentframe().f_back.f_lineno


@pytest.fixture(scope="module")
def box():
    return sl.SDF(sl.Mesh(BOX_V, BOX_F, name="box"), backend="cpu")


def near_points(n, seed=38):
    return np.random.default_rng(seed).uniform(-0.5, 1.5, (n, 3))


# ---- 3. results that stay true ----------------------------------------------------------------

@pytest.mark.parametrize("dtype, strided", [(np.float64, False), (np.float32, False), (np.float64, True)])
def test_closest_points_do_not_follow_the_callers_array(box, dtype, strided):
    original = near_points(200).astype(dtype)
    points = np.asfortranarray(original) if strided else original.copy()
    r = box.query(points)
    expected = box.query(original.copy())
    points[:] = 7.0  # the caller reuses its buffer before reading the lazy results
    np.testing.assert_array_equal(r.closest_point, expected.closest_point)
    np.testing.assert_array_equal(r.barycentric, expected.barycentric)


OBJ_WITH_REPAIRS = """\
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
v 1 0 0
v 0.5 0.5 0.5
f 1 4 3 2
f 5 6 7 8
f 1 9 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
f 1 10 10
"""
# 12 triangles of quads (the bottom quad's first corner 1, a welded copy 9 of vertex 2 in
# the front face), then a triangle with a repeated vertex that preparation drops.


def test_input_numbering_holds_for_a_file_loaded_mesh(tmp_path):
    path = tmp_path / "repaired.obj"
    path.write_text(OBJ_WITH_REPAIRS)
    mesh = sl.load_mesh(str(path))
    V, F = mesh.input_vertices, mesh.input_faces
    assert V.shape == (10, 3) and F.shape == (13, 3)
    assert mesh.report["welded_vertices"] == 1 and mesh.report["degenerate_triangles"] == 1
    assert len(mesh.faces) == 12 and len(mesh.vertices) == 8  # the prepared mesh differs
    np.testing.assert_array_equal(V[:9], np.loadtxt(str(path), usecols=(1, 2, 3), max_rows=9))
    r = sl.SDF(mesh, backend="cpu").query(near_points(500))
    assert r.triangle.max() < 12  # the dropped face 12 is never the closest
    rebuilt = (r.barycentric[:, :, None] * V[F[r.triangle]]).sum(axis=1)
    np.testing.assert_allclose(rebuilt, r.closest_point, rtol=0, atol=1e-14)
    # The array-made mesh's own arrays are its input.
    m = sl.Mesh(BOX_V, BOX_F)
    np.testing.assert_array_equal(m.input_vertices, BOX_V)
    np.testing.assert_array_equal(m.input_faces, BOX_F)


# ---- 4. a .vti cut inside its gradient --------------------------------------------------------

def test_a_vti_cut_inside_its_gradient_array_is_refused(tmp_path):
    n = 6
    x = np.linspace(0, 1, n)
    distance = (x[None, None, :] + x[None, :, None] + x[:, None, None]).astype(np.float64)
    gradient = np.broadcast_to(np.array([1.0, 1.0, 1.0]) / np.sqrt(3), (n, n, n, 3)).copy()
    sl.Field(distance, (0, 0, 0), 0.2, "cc", gradient).write(str(tmp_path / "whole.vti"), dtype="float32")
    whole = (tmp_path / "whole.vti").read_bytes()
    cut = tmp_path / "cut.vti"
    cut.write_bytes(whole[:len(whole) - 400])  # 400 bytes short: inside the gradient array
    with pytest.raises(ValueError, match=r"cut\.vti: .*array 'gradient' needs 2592 bytes .*truncated"):
        sl.read_field(str(cut))
    # A lying byte count is named too.
    at = whole.index(b"_", whole.index(b"<AppendedData")) + 1
    lie = bytearray(whole)
    lie[at:at + 8] = (10**6).to_bytes(8, "little")
    (tmp_path / "lie.vti").write_bytes(bytes(lie))
    with pytest.raises(ValueError, match=r"array 'distance' declares 1000000 bytes"):
        sl.read_field(str(tmp_path / "lie.vti"))
    pytest.importorskip("vtk")
    f = sl.read_field(str(tmp_path / "whole.vti"))
    np.testing.assert_allclose(np.asarray(f.values), distance, rtol=1e-7)


# ---- 5. the winding number: fast with its bound, or exact ---------------------------------------

def solid_angle_sum(V, F, p):
    """The generalized winding number by the direct sum of Van Oosterom & Strackee's solid angles."""
    a, b, c = V[F[:, 0]] - p, V[F[:, 1]] - p, V[F[:, 2]] - p
    la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
    num = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la + np.einsum("ij,ij->i", c, a) * lb
    return 2 * np.arctan2(num, den).sum() / (4 * np.pi)


def overlapping_spheres():
    """Two overlapping spheres as one mesh (the winding number is 2 where they overlap)."""
    s = sl.load_mesh("shape:sphere")
    V, F = s.vertices, s.faces
    return np.vstack([V, V + [0.6, 0.1, 0.05]]), np.vstack([F, F + len(V)])


def test_winding_fast_is_within_its_bound_and_exact_is_the_direct_sum():
    V, F = overlapping_spheres()
    mesh = sl.Mesh(V, F, name="overlap")
    rng = np.random.default_rng(5)
    lo, hi = V.min(axis=0), V.max(axis=0)
    points = rng.uniform(lo - 0.1, hi + 0.1, (120, 3))
    s = sl.SDF(mesh, backend="cpu")
    fast, exact = s.query(points, winding=True), s.query(points, winding="exact")
    truth = np.array([solid_angle_sum(mesh.vertices, mesh.faces, p) for p in points])
    np.testing.assert_allclose(exact.winding, truth, rtol=0, atol=1e-11)
    assert exact.winding_error_bound is None
    assert fast.winding_error_bound is not None and (fast.winding_error_bound >= 0).all()
    assert (np.abs(fast.winding - truth) <= fast.winding_error_bound + 1e-11).all()
    np.testing.assert_array_equal(s.query(points, winding="fast").winding, fast.winding)
    assert np.abs(exact.winding - 2).min() < 1e-9  # some points are in both spheres
    with pytest.raises(ValueError, match=r"winding: expected False, True .* \"exact\", got 'precise'"):
        s.query(points, winding="precise")
    assert "not exact" in type(fast).winding.__doc__.lower()


# ---- 7. messages --------------------------------------------------------------------------------

def test_reconstruct_out_of_memory_is_a_memory_error_with_the_size():
    f = sl.Field(np.zeros((4, 4, 4)), (0, 0, 0), 1.0)
    huge = np.broadcast_to(np.zeros(3, np.float32), (1 << 40, 3))  # no memory, 26 TB as float64
    with pytest.raises(MemoryError, match=r"points: out of memory converting 3298534883328 values of dtype "
                                          r"float32 to float64 \(.*TiB\)"):
        f.reconstruct(huge)


def test_warnings_point_at_the_callers_line(tmp_path):
    open_box = BOX_F[:-2]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = here() + 1
        sl.Mesh(BOX_V, open_box, name="open")
    assert caught and all(w.filename == __file__ and w.lineno == line for w in caught), \
        [(w.filename, w.lineno) for w in caught]
    path = tmp_path / "open.obj"
    path.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in BOX_V) +
                    "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in open_box))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = here() + 1
        sl.SDF(str(path), backend="cpu")  # through the package's Python parts (as_mesh)
    assert caught and all(w.filename == __file__ and w.lineno == line for w in caught), \
        [(w.filename, w.lineno) for w in caught]
    mesh = sl.Mesh(BOX_V, open_box, name="open")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = here() + 1
        sl.SDF(mesh, backend="cpu")  # sign="auto" chose the winding number: an SdfWarning of the task
    assert [w.category for w in caught] == [sl.SdfWarning]
    assert caught[0].filename == __file__ and caught[0].lineno == line, (caught[0].filename, caught[0].lineno)


def test_an_unsigned_face_index_is_shown_as_written():
    faces = BOX_F.astype(np.uint64)
    faces[3, 1] = np.uint64(2**64 - 1)
    with pytest.raises(ValueError, match=r"faces\[3, 1\] = 18446744073709551615 is not a vertex index"):
        sl.Mesh(BOX_V, faces)


def test_one_bad_row_is_named_alike_in_every_message(box):
    nan_row = np.zeros((3, 3))
    nan_row[1, 2] = np.nan
    far_row = np.zeros((3, 3))
    far_row[1, 0] = 1e20
    with pytest.raises(ValueError, match=r"points: row 1 is not three finite numbers"):
        box.query(nan_row)
    with pytest.raises(ValueError, match=r"query points: row 1 has a coordinate of magnitude 1e\+20"):
        sl.SDF(sl.Mesh(BOX_V, BOX_F), backend="cpu", precision="float").query(far_row)


def test_sdf_takes_progress_as_query_does():
    # Issue 39: sl.sdf refused progress= for every value while its message listed it as valid.
    mesh = sl.as_mesh((BOX_V, BOX_F))
    points = np.random.default_rng(39).uniform(-1.0, 2.0, (20000, 3))
    want = sl.query(mesh, points).distance
    calls = []
    for progress in (None, False, lambda done, total: calls.append((done, total))):
        np.testing.assert_array_equal(sl.sdf(mesh, points, progress=progress), want)
    assert calls and calls[-1] == (20000, 20000)


def test_the_vdb_refusal_does_not_call_a_field_file_lossless(tmp_path):
    # Issue 39: the message called a field file (float32 unless the Field is float64) "lossless".
    with pytest.raises(ValueError) as raised:
        sl.read_field(str(tmp_path / "f.vdb"))
    assert "lossless" not in str(raised.value) and 'dtype="float64"' in str(raised.value)


def test_the_arrays_axis_order_is_said_where_users_look():
    # Issue 39: values are indexed [z, y, x] while resolution and origin are (x, y, z).
    for attribute in ("values", "resolution", "origin"):
        doc = getattr(sl.Field, attribute).__doc__
        assert "[z, y, x]" in doc or "values[0, 0, 0]" in doc, attribute
    f = sl.Field(np.arange(24.0).reshape(2, 3, 4), (0.0, 0.0, 0.0), 1.0)
    assert f.resolution == (4, 3, 2) and f.values.shape == (2, 3, 4)
    np.testing.assert_array_equal(f.points()[1, 2, 3], [3.0, 2.0, 1.0])


def test_wrong_arguments_are_named_not_dumped(tmp_path):
    # Issue 39: SDF.sample(band_width=...) and render(path) gave pybind11's signature dumps.
    s = sl.SDF(sl.as_mesh((BOX_V, BOX_F)))
    with pytest.raises(TypeError, match=r"SDF.sample\(\): unexpected keyword 'band_width'.*SDF\(mesh, band_width=\.\.\.\)"):
        s.sample(band_width=0.1)
    with pytest.raises(TypeError, match=r"render\(\): field: expected an sdf_lattices.Field .* got str: read it first"):
        sl.render(str(tmp_path / "x.json"))
    f = s.sample(resolution=8)  # the wrapped calls still work, with their own keywords
    assert sl.render(f, size=16).shape[:2] == (16, 16)
    assert s.sample.__doc__ == sl._core.SDF.sample.__doc__


def test_build_info_lists_the_cuda_architectures():
    # Issue 39 item 3: build_info() says which GPUs the build's code runs on, the list CMake
    # compiled for (read back from the build's CMakeCache.txt where the build is at hand).
    cuda = sl.build_info()["optional"]["cuda"]
    if not cuda["found"]:
        pytest.skip("built without the CUDA backend")
    archs = cuda["architectures"]
    assert archs and all(re.fullmatch(r"\d+(-real|-virtual)?", a) for a in archs), archs
    cache = os.path.join(os.environ.get("SDF_BUILD_DIR", ""), "CMakeCache.txt")
    if os.path.exists(cache):
        line = next(l for l in open(cache) if l.startswith("CMAKE_CUDA_ARCHITECTURES:"))
        assert archs == line.split("=", 1)[1].strip().split(";")
