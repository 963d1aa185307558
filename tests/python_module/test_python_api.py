"""The Python package's API around the bound object (issues 23 and 24): SDF built once and
queried many times, meshes as users hold them, the outputs users expect, fields framed by
the caller, read_field of every written format, and Python manners (warnings, progress,
Ctrl-C, exception types, stubs).

Truth is independent: the box's exact distance (box_sdf), NumPy's own arithmetic on the
returned closest points and barycentric coordinates, and the existing path's numbers
(query() equals sdf-query bit for bit: test_sdf_lattices.py).
"""
import ast
import os
import re
import signal
import subprocess
import sys
import textwrap
import types
import warnings

import numpy as np
import pytest

import sdf_lattices as sl
from test_sdf_lattices import HALF, box_arrays, box_sdf, random_points, same_bits

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))


def grids(arrays):
    """A field's arrays as a list of grids: [cc] or [primary, secondary]."""
    return list(arrays) if isinstance(arrays, tuple) else [arrays]


@pytest.fixture(scope="module")
def box():
    v, f = box_arrays()
    return sl.Mesh(v, f, name="box")


@pytest.fixture(scope="module")
def torus():
    return sl.load_mesh("shape:torus")


# ---- the bound object (issue 23 item 2) ------------------------------------------------------

@pytest.mark.parametrize("method", ["bvh", "brute_force"])
@pytest.mark.parametrize("sign", ["auto", "pseudonormal", "winding"])
def test_sdf_object_queries_equal_query_bit_for_bit(torus, method, sign):
    p = random_points(1200, -1.6, 1.6, seed=21)
    bound = sl.SDF(torus, backend="cpu", method=method, sign=sign)
    once = sl.query(torus, p, backend="cpu", method=method, sign=sign)
    for chunk in (p, p[:1], p[517:900]):  # many queries of one build, any sizes
        r = bound.query(chunk)
        ref = sl.query(torus, chunk, backend="cpu", method=method, sign=sign)
        assert same_bits(r.distance, ref.distance) and same_bits(r.gradient, ref.gradient)
        assert np.array_equal(r.triangle, ref.triangle)
    assert same_bits(bound.query(p).distance, once.distance)
    assert bound.mesh.name == torus.name and bound.sampler.startswith("cpu/" + method)


def test_sdf_object_samples_equal_sample_bit_for_bit(torus):
    bound = sl.SDF(torus, backend="cpu", bcc_strategy="two_grids")
    for lattice, resolution in [("cc", (9, 10, 11)), ("bcc", (7, 8, 12))]:
        a = bound.sample(lattice=lattice, resolution=resolution, margin=0.15)
        b = sl.sample(torus, lattice=lattice, resolution=resolution, margin=0.15, backend="cpu")
        assert len(grids(a.values)) == (2 if lattice == "bcc" else 1)
        for x, y in zip(grids(a.values), grids(b.values)):
            assert same_bits(x, y)


def test_sdf_object_repr_and_properties(box):
    bound = sl.SDF(box, backend="cpu")
    text = repr(bound)
    assert "SDF" in text and "'box'" in text and "cpu/bvh" in text and "pseudonormal" in text
    assert bound.sign == "pseudonormal" and bound.precision == "float" and bound.build_seconds >= 0
    r = bound.query(np.array([[2.0, 0, 0]]))
    assert re.search(r"QueryResult: 1 point, sign 'pseudonormal', sampler 'cpu/bvh/\w+', distance in \[1, 1\]", repr(r))


# ---- meshes as users hold them (issue 24 item 3) ---------------------------------------------

class TrimeshLike:
    """What trimesh.Trimesh offers the package: vertices and faces arrays."""

    def __init__(self, vertices, faces):
        self.vertices, self.faces = vertices, faces


@pytest.mark.parametrize("vdtype", [np.float64, np.float32, np.float16, np.int32])
@pytest.mark.parametrize("fdtype", [np.int64, np.int32, np.uint32, np.int16, np.uint8, np.uint64])
def test_any_float_and_integer_dtype_is_a_mesh(vdtype, fdtype):
    v, f = box_arrays(half=np.array([2.0, 1.0, 1.0]))  # exactly representable in every dtype above
    p = random_points(50, -3, 3, seed=4)
    ref = sl.query((v, f), p, backend="cpu")
    r = sl.query((v.astype(vdtype), f.astype(fdtype)), p, backend="cpu")
    assert same_bits(r.distance, ref.distance)


def test_trimesh_like_objects_paths_and_meshes_are_accepted(tmp_path, box):
    v, f = box_arrays()
    p = random_points(200, seed=8)
    d, _ = box_sdf(p)
    obj = tmp_path / "b.obj"
    obj.write_text("".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in v) +  # explicit formats: NumPy 2's
                   "".join(f"f {a + 1:d} {b + 1:d} {c + 1:d}\n" for a, b, c in f))     # repr is np.float64(...)
    for mesh in (box, (v, f), [v, f], TrimeshLike(v, f), str(obj), obj):
        assert np.max(np.abs(sl.sdf(mesh, p) - d)) < 1e-12
    assert sl.as_mesh(TrimeshLike(v, f)).name == "TrimeshLike"


def test_something_else_is_a_type_error_naming_what_is_accepted():
    with pytest.raises(TypeError, match=r"mesh: expected an sdf_lattices.Mesh, a mesh file path, .*Open3D.*trimesh.*got builtins.int"):
        sl.query(42, np.zeros((1, 3)))
    with pytest.raises(TypeError, match="mesh: expected"):
        sl.SDF({"vertices": 1})
    with pytest.raises(TypeError, match="faces: expected an integer array"):
        sl.sdf((np.zeros((3, 3)), np.zeros((1, 3))), np.zeros((1, 3)))


def test_open3d_legacy_and_tensor_meshes():
    o3d = pytest.importorskip("open3d")  # Debian python3-open3d (scripts/debian-packages.txt, peers)
    v, f = box_arrays()
    legacy = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f.astype(np.int32)))
    tensor = o3d.t.geometry.TriangleMesh.from_legacy(legacy)
    p = random_points(300, seed=9)
    d, _ = box_sdf(p)
    for mesh in (legacy, tensor):
        r = sl.query(mesh, p, backend="cpu")
        assert np.max(np.abs(r.distance - d)) < 1e-12
        assert sl.as_mesh(mesh).faces.shape == (12, 3)
    # Open3D's own (unsigned) distance on the same points (its RaycastingScene, float32).
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(tensor)
    theirs = scene.compute_distance(o3d.core.Tensor(p.astype(np.float32))).numpy()
    assert np.max(np.abs(theirs - np.abs(d))) < 1e-5


# ---- the outputs users expect (issue 24 item 4) ----------------------------------------------

def test_closest_point_barycentrics_and_triangle_in_the_callers_order():
    """An inward box (so preparation flips every triangle) with shuffled faces: the triangle
    index is the caller's, and its barycentrics weigh the caller's face's vertices."""
    v, f = box_arrays()
    rng = np.random.default_rng(3)
    f = f[rng.permutation(len(f))][:, ::-1]  # inward, shuffled
    mesh = sl.Mesh(v, f)
    assert mesh.report["flipped"]
    p = random_points(2000, seed=12)
    r = sl.query(mesh, p, backend="cpu", precision="double")
    d, _ = box_sdf(p)
    assert np.max(np.abs(r.distance - d)) < 1e-12
    # The closest point is at distance |d| from p, along the gradient.
    assert np.allclose(np.linalg.norm(p - r.closest_point, axis=1), np.abs(r.distance), atol=1e-12)
    assert np.allclose(p - r.distance[:, None] * r.gradient, r.closest_point, atol=1e-12)
    # Barycentrics of the caller's face vertices, in the caller's order.
    b = r.barycentric
    assert np.all(b >= -1e-12) and np.allclose(b.sum(axis=1), 1, atol=1e-12)
    corners = v[f[r.triangle]]  # (N, 3 vertices, 3 coordinates)
    assert np.allclose(np.einsum("nk,nkc->nc", b, corners), r.closest_point, atol=1e-12)


def test_unsigned_mode_and_the_sign_mode_used(box):
    p = random_points(500, seed=13)
    signed = sl.query(box, p, backend="cpu")
    unsigned = sl.query(box, p, backend="cpu", sign="none")
    assert signed.sign == "pseudonormal" and unsigned.sign == "none"
    assert same_bits(unsigned.distance, np.abs(signed.distance))
    assert same_bits(unsigned.gradient, signed.gradient * np.where(signed.distance < 0, -1.0, 1.0)[:, None])
    open_box = sl.Mesh(*box_arrays(skip_face=2))
    with pytest.warns(sl.SdfWarning, match="sign auto for mesh"):
        assert sl.SDF(open_box, backend="cpu").sign == "winding"
    f = sl.sample(box, lattice="cc", resolution=5, sign="none", backend="cpu")
    assert f.values.min() >= 0 and f.sampler["sign"]["mode"] == "none"
    with pytest.raises(ValueError, match=r'SDF\(\): key \'sign\': unknown value "unsigned"; expected one of "auto", "pseudonormal", "winding" or "none"'):
        sl.SDF(box, sign="unsigned")


def test_sampler_keywords_are_the_config_codecs(box):
    """Every call's sampler keywords go through the one options codec: an unknown keyword is
    refused as an unknown config key is (the key, the nearest name, every accepted one), and
    the codec's keys beyond the old keyword lists work (band_width)."""
    with pytest.raises(ValueError, match=r"sample\(\): unknown key 'bandwidth'; did you mean 'band_width'\? "
                                         r"\(valid here: mesh, lattice, .*distributed, backend, method, kernel, .*band_width.*\)"):
        sl.sample(box, resolution=5, bandwidth=0.1)
    with pytest.raises(ValueError, match=r"query\(\): unknown key 'treads'; did you mean 'threads'\?"):
        sl.query(box, np.zeros((1, 3)), treads=1)
    with pytest.raises(ValueError, match=r"SDF\(\): key 'threads': expected a thread count \(0 = all cores\): 0 or a positive number, got -1"):
        sl.SDF(box, threads=-1)
    with pytest.raises(ValueError, match=r"sdf\(\): key 'kernel': \"backend\": \"auto\" takes no kernel"):
        sl.sdf(box, np.zeros((1, 3)), kernel="brick")
    with pytest.raises(ValueError, match=r"SDF\(\): key 'progress': progress goes to Python"):
        sl.SDF(box, progress=True)
    with pytest.raises(TypeError, match=r"sample\(\): key 'backend': expected a str, a number or a bool, got list"):
        sl.sample(box, resolution=5, backend=["cpu"])
    # devices (issue 36): "all" or a list of GPUs; the CPU backend refuses a list, takes "all".
    with pytest.raises(ValueError, match=r"sampler.devices: a list of CUDA devices needs the backend cuda"):
        sl.SDF(box, backend="cpu", devices=[0, 1])
    with pytest.raises(ValueError, match=r"SDF\(\): key 'devices': expected \"all\" or a list of distinct CUDA device ordinals"):
        sl.SDF(box, backend="cpu", devices=[0, 0])
    with pytest.raises(ValueError, match=r"sample\(\): key 'devices': expected \"all\" or a list"):
        sl.sample(box, resolution=5, backend="cpu", devices="every")
    assert same_bits(sl.sample(box, resolution=6, backend="cpu", devices="all").values,
                     sl.sample(box, resolution=6, backend="cpu").values)
    # The codec's keys all work from Python: a narrow band equals the full field clamped to +-W.
    full = sl.sample(box, resolution=6, backend="cpu")
    band = sl.sample(box, resolution=6, backend="cpu", band_width=np.float32(0.25))
    v = full.values
    inside = np.abs(v) <= 0.25
    assert np.array_equal(band.values[inside], v[inside])
    assert np.array_equal(band.values[~inside], np.where(v[~inside] < 0, -0.25, 0.25))
    assert band.sampler["band"]["width"] == 0.25


def test_winding_number_is_occupancy(box):
    p = random_points(400, seed=14)
    r = sl.SDF(box, backend="cpu").query(p, winding=True)
    assert r.winding.shape == (400,)
    inside = r.distance < -1e-3
    outside = r.distance > 1e-3
    assert np.all(np.abs(r.winding[inside] - 1) < 0.05) and np.all(np.abs(r.winding[outside]) < 0.05)
    assert sl.query(box, p).winding is None


# ---- fields as users frame them (issue 24 item 5) --------------------------------------------

def test_sample_on_bounds_and_spacing_is_framed_exactly(box):
    bounds = ((-1.5, -1.0, -0.5), (1.5, 1.0, 0.5))
    f = sl.sample(box, lattice="cc", bounds=bounds, spacing=0.25, backend="cpu", precision="double")
    assert f.origin == bounds[0] and f.spacing == 0.25 and f.resolution == (13, 9, 5)
    pts = f.points()
    assert pts.shape == (5, 9, 13, 3) and np.allclose(pts[-1, -1, -1], bounds[1])
    d, _ = box_sdf(pts.reshape(-1, 3))
    assert np.max(np.abs(f.values.reshape(-1) - d)) < 1e-14
    g = sl.sample(box, lattice="cc", bounds=bounds, resolution=(13, 9, 5), backend="cpu")
    assert g.spacing == 0.25 and g.origin == bounds[0]
    h = sl.sample(box, lattice="cc", origin=(0, 0, 0), spacing=0.5, resolution=3, backend="cpu")
    assert h.origin == (0, 0, 0) and h.resolution == (3, 3, 3)


def test_bcc_on_bounds_and_spacing(box):
    f = sl.sample(box, lattice="bcc", bounds=((-1, -1, -1), (1, 1, 1)), spacing=0.5, backend="cpu", precision="double")
    assert f.resolution == (5, 5, 10) and f.origin == (-1, -1, -1)
    primary, secondary = f.points()
    assert np.allclose(secondary[0, 0, 0], (-0.75, -0.75, -0.75))
    d, _ = box_sdf(secondary.reshape(-1, 3))
    assert np.max(np.abs(f.values[1].reshape(-1) - d)) < 1e-14


def test_framing_errors_name_the_argument(box):
    with pytest.raises(ValueError, match="bounds: give exactly one of spacing and resolution"):
        sl.sample(box, bounds=((-1, -1, -1), (1, 1, 1)))
    with pytest.raises(ValueError, match="bounds: expected min < max"):
        sl.sample(box, bounds=((1, -1, -1), (-1, 1, 1)), spacing=0.1)
    with pytest.raises(ValueError, match="spacing: expected a finite distance > 0"):
        sl.sample(box, spacing=-1)
    with pytest.raises(ValueError, match="origin: needs spacing and resolution"):
        sl.sample(box, origin=(0, 0, 0), spacing=0.1)
    with pytest.raises(ValueError, match="margin: not with bounds"):
        sl.sample(box, bounds=((-1, -1, -1), (1, 1, 1)), spacing=0.5, margin=0.2)


def test_field_from_arrays_reconstructs_and_writes(tmp_path):
    h, origin = 0.1, (0.0, 0.0, 0.0)
    z, y, x = np.meshgrid(np.arange(8), np.arange(7), np.arange(6), indexing="ij")
    values = 2.0 * x * h - 3.0 * y * h + 0.5 * z * h + 1.0  # linear: trilinear is exact
    f = sl.Field(values, origin, h)
    assert f.lattice == "cc" and f.resolution == (6, 7, 8) and f.gradient is None
    assert np.allclose(f.points()[1, 2, 3], (0.3, 0.2, 0.1))
    p = np.array([[0.21, 0.33, 0.47], [0.05, 0.55, 0.6]])
    vals, grads = f.reconstruct(p, interpolator="trilinear")
    assert np.allclose(vals, 2 * p[:, 0] - 3 * p[:, 1] + 0.5 * p[:, 2] + 1, atol=1e-12)
    assert np.allclose(grads, [[2, -3, 0.5]] * 2, atol=1e-9)
    f.write(str(tmp_path / "mine.json"))
    assert sl.read_field(str(tmp_path / "mine.json")).resolution == (6, 7, 8)
    with pytest.raises(ValueError, match="secondary grid"):
        sl.Field((values, values), origin, h, lattice="bcc")


def test_reconstruct_outside_the_domain_is_nan_clamp_or_error(box):
    f = sl.sample(box, lattice="cc", resolution=8, backend="cpu")
    p = np.array([[0.1, 0.1, 0.1], [10.0, 10.0, 10.0]])
    nan_v, nan_g = f.reconstruct(p)  # the default: NaN outside
    assert np.isfinite(nan_v[0]) and np.isnan(nan_v[1]) and np.all(np.isnan(nan_g[1]))
    clamped, _ = f.reconstruct(p, outside="clamp")
    assert clamped[0] == nan_v[0] and np.isfinite(clamped[1])
    with pytest.raises(ValueError, match=r"points: row 1 \(10, 10, 10\) lies outside the field's domain"):
        f.reconstruct(p, outside="error")
    with pytest.raises(ValueError, match='outside: unknown value "zero"; expected one of "nan", "clamp" or "error"'):
        f.reconstruct(p, outside="zero")


def test_read_field_reads_what_write_writes_or_says_why_not(tmp_path, box):
    cc = sl.sample(box, lattice="cc", resolution=(5, 6, 7), backend="cpu", precision="double")
    bcc = sl.sample(box, lattice="bcc", resolution=(5, 5, 8), backend="cpu", precision="double")
    for name, field in (("c", cc), ("b", bcc)):
        for ext in ("npz", "vti"):
            if ext == "vti":
                pytest.importorskip("vtk")
            path = str(tmp_path / f"{name}.{ext}")
            field.write(path, dtype="float64")
            back = sl.read_field(path)
            assert back.lattice == field.lattice and back.resolution == field.resolution
            assert back.origin == field.origin and back.spacing == field.spacing
            for x, y in zip(grids(back.values), grids(field.values)):
                assert same_bits(x, y), (name, ext)
    cc.write(str(tmp_path / "c.npy"))
    with pytest.raises(ValueError, match=r"c\.npy: a \.npy file holds the values without their lattice"):
        sl.read_field(str(tmp_path / "c.npy"))
    with pytest.raises(ValueError, match=r"\.vdb file holds the field only in a narrow band"):
        sl.read_field(str(tmp_path / "c.vdb"))
    with pytest.raises(FileNotFoundError):
        sl.read_field(str(tmp_path / "nothing.json"))
    with pytest.raises(ValueError, match=r"unknown field file extension '\.xyz'"):
        sl.read_field(str(tmp_path / "c.xyz"))


# ---- Python manners (issue 24 item 7) --------------------------------------------------------

def test_mesh_warnings_go_through_the_warnings_module():
    with pytest.warns(sl.MeshWarning, match="boundary"):
        sl.Mesh(*box_arrays(skip_face=2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a closed box warns nothing
        sl.Mesh(*box_arrays())


def test_progress_callback_and_tqdm(monkeypatch, torus):
    calls = []
    p = random_points(20000, seed=15)
    r = sl.query(torus, p, backend="cpu", progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1] == (20000, 20000) and all(t == 20000 for _, t in calls)
    assert len(r) == 20000

    class FakeTqdm:
        made = []

        def __init__(self, total, desc, **_):
            self.total, self.desc, self.n, self.closed = total, desc, 0, False
            FakeTqdm.made.append(self)

        def update(self, k):
            self.n += k

        def close(self):
            self.closed = True

    fake = types.ModuleType("tqdm.auto")
    fake.tqdm = FakeTqdm
    monkeypatch.setitem(sys.modules, "tqdm", types.ModuleType("tqdm"))
    monkeypatch.setitem(sys.modules, "tqdm.auto", fake)
    sl.sample(torus, resolution=12, backend="cpu", progress=True)
    bar = FakeTqdm.made[-1]
    assert bar.total == 12 ** 3 and bar.n == 12 ** 3 and bar.closed and "sampling 'torus'" in bar.desc
    with pytest.raises(TypeError, match="progress: expected"):
        sl.query(torus, p, progress="yes")


def test_an_exception_in_the_progress_callback_stops_the_call(torus):
    def stop(done, total):
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        sl.query(torus, random_points(200000, seed=16), backend="cpu", method="brute_force", threads=1, progress=stop)


CTRL_C = textwrap.dedent("""
    import sys, time, numpy as np, sdf_lattices as sl
    mesh = sl.load_mesh("shape:sphere")
    p = np.random.default_rng(1).uniform(-2, 2, size=(4_000_000, 3))
    print("started", flush=True)
    t = time.monotonic()
    try:
        sl.query(mesh, p, backend="cpu", method="brute_force", threads=1)
        print("finished", time.monotonic() - t, flush=True)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic() - t, flush=True)
""")


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT")
def test_ctrl_c_stops_a_long_query():
    """SIGINT 1 s into a query of several minutes raises KeyboardInterrupt soon after."""
    child = subprocess.Popen([sys.executable, "-c", CTRL_C], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "started"
    import time
    time.sleep(1.0)
    sent = time.monotonic()
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=120)
    waited = time.monotonic() - sent
    assert out.startswith("interrupted"), (out, err)
    # Generous for a loaded 2-core machine; the whole query takes minutes.
    assert waited < 10, waited


def test_exception_types():
    with pytest.raises(TypeError):
        sl.Mesh(np.zeros((3, 3)), np.zeros((1, 3)))
    with pytest.raises(ValueError):
        sl.query("shape:box", np.zeros((2, 2)))
    with pytest.raises(RuntimeError):
        sl.load_mesh("/no/such/mesh.obj")
    with pytest.raises(TypeError, match="points: expected an \\(N, 3\\) array of numbers, got str"):
        sl.query("shape:box", "not points")
    with pytest.raises(TypeError, match="points: expected an \\(N, 3\\) array of numbers, got ndarray of dtype complex128"):
        sl.SDF("shape:box").query(np.zeros((2, 3), dtype=complex))


def test_type_stubs_name_every_public_symbol():
    stub = os.path.join(os.path.dirname(sl.__file__), "__init__.pyi")
    assert os.path.exists(stub) and os.path.exists(os.path.join(os.path.dirname(sl.__file__), "py.typed"))
    tree = ast.parse(open(stub).read())
    names = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    names |= {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    public = {n for n in dir(sl) if not n.startswith("_")} - {"annotations"}
    assert public - names == set(), "missing from the stubs"
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    for cls in ("Mesh", "SDF", "QueryResult", "Field"):
        members = {m.name for m in classes[cls].body if isinstance(m, ast.FunctionDef)}
        members |= {m.target.id for m in classes[cls].body if isinstance(m, ast.AnnAssign)}
        actual = {n for n in vars(getattr(sl, cls)) if not n.startswith("_")}
        assert actual - members == set(), cls


def test_the_notebook_example_in_the_docs_runs(tmp_path, monkeypatch):
    """docs/python.md's example, every python block in order, headless (matplotlib Agg)."""
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    text = open(os.path.join(REPO, "docs", "python.md")).read()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)
    scope = {}
    for block in blocks:
        exec(compile(block, "docs/python.md", "exec"), scope)
    assert os.path.exists(tmp_path / "torus_slice_and_isosurface.png")


def test_a_query_says_how_it_went_over_the_devices():
    # Issue 36: a job below the split threshold (min_points_per_device) runs on one device, and says so.
    v, f = box_arrays()
    d = sl.SDF((v, f), backend="cpu").query(np.zeros((10, 3))).devices
    assert d == {"count": 1, "used": 1, "split": False, "min_points_per_device": 2 ** 23}
    d = sl.SDF((v, f), backend="cpu", min_points_per_device=5).query(np.zeros((10, 3))).devices
    assert d["min_points_per_device"] == 5 and d["used"] == 1
