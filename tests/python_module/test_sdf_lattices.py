"""The Python module sdf_lattices against the tools (bit for bit) and analytic truth.

Run by CTest (python_module) with PYTHONPATH=build/python and the tools' paths in SDF_QUERY,
SDF_EVAL and RUN_EXPERIMENT. Independent readers: NumPy's np.load/np.save for .npy files,
np.fromfile for the field files' raw channels.
"""
import glob
import json
import os
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import sdf_lattices as sl

SDF_QUERY = os.environ.get("SDF_QUERY", "build/bin/sdf-query")
SDF_EVAL = os.environ.get("SDF_EVAL", "build/bin/sdf-eval")
RUN_EXPERIMENT = os.environ.get("RUN_EXPERIMENT", "build/bin/run-experiment")

HALF = np.array([1.0, 0.5, 0.25])  # the analytic box's half extents


def box_arrays(half=HALF, skip_face=None):
    """An axis-aligned box centred at the origin: 8 vertices, 12 outward triangles."""
    corners = np.array([[(-1) ** (1 - ((c >> k) & 1)) for k in range(3)] for c in range(8)], dtype=float)
    quads = [(1, 3, 7, 5), (0, 4, 6, 2), (2, 6, 7, 3), (0, 1, 5, 4), (4, 5, 7, 6), (0, 2, 3, 1)]
    faces = []
    for f, (a, b, c, d) in enumerate(quads):
        if f != skip_face:
            faces += [(a, b, c), (a, c, d)]
    return corners * half, np.array(faces, dtype=np.int64)


def box_sdf(p, half=HALF):
    """The exact signed distance and gradient of the box (Quilez's formula)."""
    q = np.abs(p) - half
    outside = np.maximum(q, 0.0)
    out_len = np.linalg.norm(outside, axis=1)
    inner = np.minimum(q.max(axis=1), 0.0)
    d = out_len + inner
    g = np.where(out_len[:, None] > 0, outside / np.where(out_len > 0, out_len, 1)[:, None], 0.0)
    axis = q.argmax(axis=1)
    inside_g = np.zeros_like(p)
    inside_g[np.arange(len(p)), axis] = 1.0
    g = np.where((out_len > 0)[:, None], g, inside_g) * np.sign(p)
    return d, g


def random_points(n, lo=-2.0, hi=2.0, seed=7):
    return np.random.default_rng(seed).uniform(lo, hi, size=(n, 3))


def run(cmd, cwd=None, check=True):
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if check:
        assert r.returncode == 0, f"{cmd}: exit {r.returncode}\n{r.stderr}"
    return r


def same_bits(a, b):
    """Equal to the last bit (0.0 and -0.0 differ; NaN never appears here)."""
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


@pytest.fixture(scope="module")
def box():
    v, f = box_arrays()
    return sl.Mesh(v, f, name="box")


# ---- meshes --------------------------------------------------------------------------------

def test_mesh_from_arrays_reports_a_closed_outward_box(box):
    assert box.closed and box.consistently_oriented and box.sign_reliable
    assert box.components == 1
    assert box.orientation == "outward"
    assert box.warnings == []
    assert box.faces.shape == (12, 3) and box.vertices.shape == (8, 3)
    assert np.allclose(box.bounds, [-HALF, HALF])
    assert box.report["input_triangles"] == 12 and box.report["boundary_edges"] == 0


def test_inward_box_is_flipped_and_an_open_box_warns():
    v, f = box_arrays()
    inward = sl.Mesh(v, f[:, ::-1])
    assert inward.report["flipped"] and inward.orientation == "outward (flipped from inward)"
    open_box = sl.Mesh(*box_arrays(skip_face=2))
    assert not open_box.closed and open_box.report["boundary_edges"] == 4
    assert open_box.warnings and not open_box.sign_reliable


def test_bad_arrays_raise_value_errors_naming_the_argument():
    v, f = box_arrays()
    with pytest.raises(ValueError, match=r"faces\[0, 1\] = 8 is not a vertex index"):
        sl.Mesh(v, np.array([[0, 8, 1]]))
    with pytest.raises(ValueError, match=r"vertices: expected an array of shape \(N, 3\)"):
        sl.Mesh(v[:, :2], f)
    with pytest.raises(TypeError, match="integer"):
        sl.Mesh(v, f.astype(float))
    with pytest.raises(ValueError, match="row 3 is not three finite numbers"):
        bad = v.copy()
        bad[3, 1] = np.nan
        sl.Mesh(bad, f)


def test_load_mesh_reads_files_and_shapes(tmp_path):
    v, f = box_arrays()
    obj = tmp_path / "b.obj"
    obj.write_text("".join(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in v) +  # explicit formats: NumPy 2's
                   "".join(f"f {a + 1:d} {b + 1:d} {c + 1:d}\n" for a, b, c in f))     # repr is np.float64(...)
    m = sl.load_mesh(str(obj))
    assert m.name == "b" and m.source == str(obj) and m.closed
    assert sl.load_mesh("shape:torus").components == 1


def test_load_errors_carry_the_tools_messages(tmp_path):
    missing = str(tmp_path / "no_such_mesh.obj")
    with pytest.raises(RuntimeError) as e:
        sl.load_mesh(missing)
    points = tmp_path / "p.txt"
    points.write_text("0 0 0\n")
    r = run([SDF_QUERY, missing, str(points)], check=False)
    assert r.returncode == 1
    assert r.stderr.strip() == "sdf-query: error: " + str(e.value)
    with pytest.raises(ValueError, match="did you mean .box."):
        sl.load_mesh("shape:bxo")


# ---- queries -------------------------------------------------------------------------------

@pytest.mark.parametrize("precision,tol", [("float", 1e-12), ("double", 1e-14)])
@pytest.mark.parametrize("method", ["bvh", "brute_force"])
def test_query_box_equals_the_analytic_distance(box, precision, tol, method):
    p = random_points(3000)
    r = sl.query(box, p, precision=precision, method=method)
    d, g = box_sdf(p)
    assert r.distance.shape == (3000,) and r.gradient.shape == (3000, 3) and r.triangle.shape == (3000,)
    assert np.max(np.abs(r.distance - d)) < tol
    assert np.max(np.abs(r.gradient - g)) < 1e-9
    assert r.triangle.min() >= 0 and r.triangle.max() < 12
    assert r.sampler.split("/")[1] == method  # cpu/... or cuda/... (backend auto)


def test_query_sphere_within_its_tessellation():
    sphere = sl.load_mesh("shape:sphere")  # icosphere, 4 subdivisions, radius 1: vertices on the sphere
    p = random_points(2000, seed=3)
    r = np.linalg.norm(p, axis=1)
    p = p[np.abs(r - 1) > 0.01]
    r = np.linalg.norm(p, axis=1)
    q = sl.query(sphere, p)
    sagitta = 2e-3  # > 1 - cos(angular radius of a face) at 4 subdivisions
    # The polyhedron lies inside the sphere: outside points are farther from it, inside points nearer.
    assert np.all(np.sign(q.distance) == np.sign(r - 1))
    assert np.all(q.distance >= r - 1 - 1e-12)
    assert np.all(q.distance <= r - 1 + sagitta)
    radial = p / r[:, None]
    assert np.all(np.einsum("ij,ij->i", q.gradient, radial) > 0.99)


def npy_query(tmp_path, mesh_arg, points, *options):
    pts = tmp_path / "points.npy"
    out = tmp_path / "out.npy"
    np.save(pts, points)
    if out.exists():
        out.unlink()
    run([SDF_QUERY, mesh_arg, str(pts), "--out", str(out), "--quiet", *options])
    rows = np.load(out)
    assert rows.dtype == np.float64 and rows.shape == (len(points), 5)
    return rows


@pytest.mark.parametrize("method", ["bvh", "brute_force"])
@pytest.mark.parametrize("precision", ["float", "double"])
@pytest.mark.parametrize("sign", ["auto", "pseudonormal", "winding"])
def test_query_equals_sdf_query_to_the_last_bit(tmp_path, method, precision, sign):
    mesh = sl.load_mesh("shape:torus")
    p = random_points(1500, -1.6, 1.6, seed=11)
    rows = npy_query(tmp_path, "shape:torus", p, "--method", method, "--precision", precision, "--sign", sign,
                     "--backend", "cpu")
    r = sl.query(mesh, p, backend="cpu", method=method, precision=precision, sign=sign)
    assert same_bits(r.distance, rows[:, 0])
    assert same_bits(r.gradient, np.ascontiguousarray(rows[:, 1:4]))
    assert np.array_equal(r.triangle, rows[:, 4].astype(np.int32))


@pytest.mark.skipif(not sl.cuda_available(), reason="no CUDA backend or GPU")
@pytest.mark.parametrize("method", ["bvh", "brute_force"])
def test_cuda_query_equals_sdf_query_and_the_cpu(tmp_path, method):
    mesh = sl.load_mesh("shape:torus")
    p = random_points(5000, -1.6, 1.6, seed=13)
    rows = npy_query(tmp_path, "shape:torus", p, "--method", method, "--backend", "cuda")
    r = sl.query(mesh, p, backend="cuda", method=method)
    assert r.sampler.startswith("cuda/")
    assert same_bits(r.distance, rows[:, 0])
    assert same_bits(r.gradient, np.ascontiguousarray(rows[:, 1:4]))
    cpu = sl.query(mesh, p, backend="cpu", method=method)
    assert np.max(np.abs(r.distance - cpu.distance)) < 1e-12
    t = r.timings_seconds  # the BVH sampler's own clocks: device time within the call's wall time
    assert t["total"] > 0
    if method == "bvh":
        assert 0 < t["kernel"] <= t["total"] and t["upload"] > 0 and t["download"] > 0


def test_query_timings_on_the_cpu():
    t = sl.query(sl.load_mesh("shape:torus"), random_points(1000, -1.6, 1.6, seed=3), backend="cpu").timings_seconds
    assert set(t) == {"total", "kernel", "upload", "download"}
    assert t["total"] > 0 and t["kernel"] == 0 and t["upload"] == 0 and t["download"] == 0


@pytest.mark.parametrize("backend", ["cpu", "cuda"])
def test_query_counts_its_certified_search(backend):
    """A float query counts every point certified, those re-ranked in double (a torus point's
    nearest vertex or edge is shared: exact ties) and none sent further; the double search is
    the reference and counts nothing."""
    if backend == "cuda" and not sl.cuda_available():
        pytest.skip("no CUDA backend or GPU")
    mesh, p = sl.load_mesh("shape:torus"), random_points(3000, -1.6, 1.6, seed=17)
    c = sl.query(mesh, p, backend=backend, precision="float").search_certificate
    assert set(c) == {"points", "reranked", "full_double"}
    assert c["points"] == len(p) and 0 < c["reranked"] <= len(p) and 0 <= c["full_double"] <= c["reranked"]
    assert sl.query(mesh, p, backend=backend, precision="double").search_certificate == {"points": 0, "reranked": 0, "full_double": 0}


@pytest.mark.parametrize("backend", ["cpu", "cuda"])
def test_winding_sides_from_the_nearest_triangles_equal_the_walks(backend, monkeypatch):
    """The certified winding sign's side from a float search's candidates alone (nearest_side:
    the CPU's packets, the GPU's re-rank of its listed candidates) is the side the walk to the
    closest triangle gives (SDF_WINDING_WALK_ONLY=1), at every point near the surface, where a
    vertex's fan of exact ties makes several candidates the rule."""
    if backend == "cuda" and not sl.cuda_available():
        pytest.skip("no CUDA backend or GPU")
    mesh = sl.load_mesh("shape:torus")
    v = np.asarray(mesh.vertices)
    rng = np.random.default_rng(23)
    p = v[rng.integers(0, len(v), 20000)] + rng.normal(0, 0.02, (20000, 3))
    listed = sl.SDF(mesh, backend=backend, sign="winding").query(p)
    monkeypatch.setenv("SDF_WINDING_WALK_ONLY", "1")
    walked = sl.SDF(mesh, backend=backend, sign="winding").query(p)
    assert same_bits(listed.distance, walked.distance)
    assert np.array_equal(listed.triangle, walked.triangle)
    assert 0.2 < np.mean(listed.distance < 0) < 0.8


def test_sdf_query_text_and_npy_agree_and_float32_points_are_read(tmp_path):
    p = random_points(200, seed=5)
    rows = npy_query(tmp_path, "shape:box", p, "--precision", "double")
    text = tmp_path / "p.txt"
    text.write_text("".join(f"{x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in p))
    out = run([SDF_QUERY, "shape:box", str(text), "--precision", "double"]).stdout
    assert np.array_equal(np.loadtxt(out.splitlines()), rows)
    rows32 = npy_query(tmp_path, "shape:box", p.astype(np.float32), "--precision", "double")
    r = sl.query(sl.load_mesh("shape:box"), p.astype(np.float32).astype(np.float64), precision="double")
    assert same_bits(r.distance, rows32[:, 0])


def test_query_argument_errors():
    m = sl.load_mesh("shape:box")
    with pytest.raises(ValueError, match=r'query\(\): key \'backend\': unknown value "gpu"; expected one of "auto", "cpu" or "cuda"'):
        sl.query(m, np.zeros((1, 3)), backend="gpu")
    with pytest.raises(ValueError, match="method"):
        sl.query(m, np.zeros((1, 3)), method="octree")
    with pytest.raises(ValueError, match="--sign|sign"):
        sl.query(m, np.zeros((1, 3)), sign="parity")
    with pytest.raises(ValueError, match=r"points: expected an array of shape \(N, 3\), got shape \(4,\)"):
        sl.query(m, np.zeros(4))
    assert len(sl.query(m, np.zeros((0, 3)))) == 0


def test_query_releases_the_gil():
    """A second Python thread keeps running while a query computes."""
    sphere = sl.load_mesh("shape:sphere")
    # A query long enough for the ticker's 1 ms waits on any machine (20,000 points took
    # 3 ms on a fast host): with the GIL held it would see none of them.
    n = 20000
    while True:
        p = random_points(n, seed=1)
        start = time.perf_counter()
        sl.query(sphere, p, method="brute_force", threads=1)
        if time.perf_counter() - start >= 0.05 or n >= 2_000_000:
            break
        n *= 4
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(1)
            done.wait(0.001)

    t = threading.Thread(target=tick)
    t.start()
    before = len(ticks)
    sl.query(sphere, p, method="brute_force", threads=1)
    during = len(ticks) - before
    done.set()
    t.join()
    assert during > 3


# ---- sampled fields ------------------------------------------------------------------------

@pytest.fixture(scope="module")
def experiment_fields(tmp_path_factory):
    """Fields of a run-experiment sampling run of shape:torus (float64 files), by lattice type."""
    root = tmp_path_factory.mktemp("runs")
    config = {
        "name": "module_fields", "kind": "sampling", "mesh": "shape:torus", "domain": {"margin": 0.15},
        "lattices": [{"type": "cc", "resolution": [9, 10, 11]}, {"type": "bcc", "resolution": [7, 8, 12]}],
        "sampler": {"backend": "cpu", "method": "bvh", "precision": "float", "progress": False},
        "output": {"dtype": "float64"},
    }
    path = root / "config.json"
    path.write_text(json.dumps(config))
    run([RUN_EXPERIMENT, str(path), "--output-root", str(root / "results"), "--no-cache", "--quiet"])
    headers = sorted(glob.glob(str(root / "results" / "module_fields" / "*" / "fields" / "*.json")))
    assert len(headers) == 2, headers
    return {json.load(open(h))["lattice"]["type"]: h for h in headers}


@pytest.fixture(scope="module")
def torus():
    return sl.load_mesh("shape:torus")


def grids(field_arrays, lattice):
    return list(field_arrays) if lattice == "bcc" else [field_arrays]


@pytest.mark.parametrize("lattice,resolution", [("cc", (9, 10, 11)), ("bcc", (7, 8, 12))])
def test_sample_equals_a_run_experiment_field_bit_for_bit(tmp_path, experiment_fields, torus, lattice, resolution):
    ours = sl.sample(torus, lattice=lattice, resolution=resolution, margin=0.15, backend="cpu", method="bvh")
    theirs = sl.read_field(experiment_fields[lattice])
    assert ours.lattice == theirs.lattice == lattice
    assert ours.resolution == theirs.resolution == resolution
    assert ours.origin == theirs.origin and ours.spacing == theirs.spacing
    for name in ("values", "gradient", "triangle"):
        for x, y in zip(grids(getattr(ours, name), lattice), grids(getattr(theirs, name), lattice)):
            assert same_bits(x, y), name
    # The module's writer gives the same channel bytes as run-experiment's files.
    mine = tmp_path / "mine.json"
    ours.write(str(mine), dtype="float64")
    for channel in ("distance", "gradient", "closest_triangle"):
        ref = experiment_fields[lattice].replace(".json", f".{channel}.raw")
        assert open(str(mine).replace(".json", f".{channel}.raw"), "rb").read() == open(ref, "rb").read()


def test_cc_field_layout_and_values_equal_point_queries(box):
    f = sl.sample(box, lattice="cc", resolution=(5, 6, 7), margin=0.2, backend="cpu", precision="double")
    assert f.values.shape == (7, 6, 5) and f.gradient.shape == (7, 6, 5, 3) and f.triangle.shape == (7, 6, 5)
    assert f.num_points == 5 * 6 * 7 and f.notation == "5x6x7"
    h, o = f.spacing, np.array(f.origin)
    z, y, x = np.meshgrid(np.arange(7), np.arange(6), np.arange(5), indexing="ij")
    points = o + h * np.stack([x, y, z], axis=-1).reshape(-1, 3)
    d, g = box_sdf(points)
    assert np.max(np.abs(f.values.reshape(-1) - d)) < 1e-14
    assert np.max(np.abs(f.gradient.reshape(-1, 3) - g)) < 1e-12


def test_bcc_field_is_two_cc_subgrids_half_a_spacing_apart(box):
    f = sl.sample(box, lattice="bcc", resolution=6, backend="cpu", precision="double")
    assert f.resolution == (6, 6, 12)
    primary, secondary = f.values
    assert primary.shape == (6, 6, 6) and secondary.shape == (5, 5, 5)
    assert f.gradient[1].shape == (5, 5, 5, 3)
    o0, o1 = np.array(f.grid_origins[0]), np.array(f.grid_origins[1])
    assert np.allclose(o1 - o0, f.spacing / 2)
    k, j, i = 1, 2, 3
    d, _ = box_sdf(np.array([o1 + f.spacing * np.array([i, j, k])]))
    assert abs(secondary[k, j, i] - d[0]) < 1e-14


def test_field_arrays_are_read_only_views_that_outlive_the_field(tmp_path, box):
    f = sl.sample(box, lattice="bcc", resolution=6, backend="cpu", precision="double")
    path = str(tmp_path / "box.json")
    f.write(path, dtype="float64")
    values, gradient, triangle = f.values, f.gradient, f.triangle
    assert values[1].base is not None and not values[1].flags.owndata  # a view, no copy
    del f  # the views keep the field's memory alive
    raw = {c: np.fromfile(str(tmp_path / f"box.{c}.raw"), dtype=t)  # an independent reader
           for c, t in (("distance", "<f8"), ("gradient", "<f8"), ("closest_triangle", "<i4"))}
    assert same_bits(raw["distance"], np.concatenate([v.reshape(-1) for v in values]))
    assert same_bits(raw["gradient"], np.concatenate([g.reshape(-1) for g in gradient]))
    assert np.array_equal(raw["closest_triangle"], np.concatenate([t.reshape(-1) for t in triangle]))
    for a in (*values, *gradient, *triangle):
        assert not a.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        values[0][0, 0, 0] = 1.0
    mine = values[0].copy()
    mine[0, 0, 0] = 1.0  # a copy is the caller's to change
    assert mine[0, 0, 0] == 1.0 and values[0][0, 0, 0] != 1.0


def test_resolution_and_samples_take_numpy_integers(box):
    want = sl.sample(box, lattice="bcc", resolution=6, backend="cpu", precision="double")
    for resolution in (np.int64(6), np.uint8(6), np.array([6, 6, 12]), (np.int32(6), 6, np.int16(12))):
        f = sl.sample(box, lattice="bcc", resolution=resolution, backend="cpu", precision="double")
        assert f.resolution == (6, 6, 12)
        assert same_bits(f.values[0], want.values[0])
    assert sl.sample(box, lattice="cc", samples=np.int64(64), backend="cpu").num_points > 0
    with pytest.raises(TypeError, match=r"resolution must be an integer \(Python or NumPy\), got float 6.0"):
        sl.sample(box, lattice="cc", resolution=6.0, backend="cpu")
    with pytest.raises(TypeError, match=r"resolution\[1\] must be an integer"):
        sl.sample(box, lattice="cc", resolution=[6, 6.5, 6], backend="cpu")
    with pytest.raises(ValueError, match="out of range"):
        sl.sample(box, lattice="cc", resolution=2**70, backend="cpu")


def test_write_and_read_field_round_trip_and_refuse_overwrite(tmp_path, box):
    f = sl.sample(box, lattice="bcc", resolution=(5, 5, 8), backend="cpu")
    path = str(tmp_path / "box.json")
    f.write(path, dtype="float64")
    g = sl.read_field(path)
    for x, y in zip(f.values, g.values):
        assert same_bits(x, y)
    raw = np.fromfile(str(tmp_path / "box.distance.raw"), dtype="<f8")  # an independent reader
    assert same_bits(raw, np.concatenate([f.values[0].reshape(-1), f.values[1].reshape(-1)]))
    with pytest.raises(RuntimeError, match="box.json"):
        f.write(path)
    f.write(path, overwrite=True)  # float32 now
    assert np.allclose(sl.read_field(path).values[0], f.values[0], rtol=1e-6)
    with pytest.raises(ValueError, match=r"unknown field file extension '\.xyz'"):
        f.write(str(tmp_path / "box.xyz"))


def test_write_picks_the_volume_format_by_extension(tmp_path, box):
    """Field.write(.npy/.npz/.vti/.vdb): the volume formats, read back by NumPy, VTK and
    pyopenvdb (where installed); BCC as its two CC sub-grids."""
    cc = sl.sample(box, lattice="cc", resolution=(5, 6, 7), backend="cpu", precision="double")
    cc.write(str(tmp_path / "c.npy"), dtype="float64")
    assert same_bits(np.load(str(tmp_path / "c.npy")), cc.values)
    assert same_bits(np.load(str(tmp_path / "c.gradient.npy")), cc.gradient)
    bcc = sl.sample(box, lattice="bcc", resolution=(5, 5, 8), backend="cpu", precision="double")
    bcc.write(str(tmp_path / "b.npz"), dtype="float64")
    z = np.load(str(tmp_path / "b.npz"))
    assert same_bits(z["distance_primary"], bcc.values[0]) and same_bits(z["distance_secondary"], bcc.values[1])
    try:
        import vtk
        from vtk.util.numpy_support import vtk_to_numpy
    except ImportError:
        vtk = None
    if vtk is not None:
        cc.write(str(tmp_path / "c.vti"), dtype="float64")
        r = vtk.vtkXMLImageDataReader()
        r.SetFileName(str(tmp_path / "c.vti"))
        r.Update()
        d = vtk_to_numpy(r.GetOutput().GetPointData().GetArray("distance"))
        assert same_bits(d, cc.values.reshape(-1))
    with pytest.raises(RuntimeError, match="c.npy"):
        cc.write(str(tmp_path / "c.npy"))  # never overwritten silently


def test_sample_arguments_are_checked_by_the_config_parser(box):
    with pytest.raises(ValueError, match=r"sample\(\): key 'lattice.resolution': .*third entry must be even"):
        sl.sample(box, lattice="bcc", resolution=(5, 5, 7))
    with pytest.raises(ValueError, match="exactly one of"):
        sl.sample(box, lattice="cc")
    with pytest.raises(ValueError, match=r"sample\(\): key 'kernel': unknown cpu bvh kernel \"brik\".*did you mean \"brick\""):
        sl.sample(box, lattice="cc", resolution=4, backend="cpu", kernel="brik")
    with pytest.raises(ValueError, match='lattice: unknown value "fcc"; expected one of "cc" or "bcc"'):
        sl.sample(box, lattice="fcc", resolution=4)
    f = sl.sample(box, lattice="cc", samples=1000, backend="cpu")
    assert 700 < f.num_points < 1400


# ---- reconstruction and rendering -----------------------------------------------------------

def test_reconstruct_equals_sdf_eval(tmp_path, box):
    f = sl.sample(box, lattice="bcc", resolution=(8, 8, 16), backend="cpu")
    path = str(tmp_path / "f.json")
    f.write(path, dtype="float64")
    p = random_points(300, -0.9, 0.9, seed=2)
    np.save(tmp_path / "p.npy", p)
    for interpolator, derivatives in [("bcc_cubic", "true"), ("bcc_linear", "fd"), ("bcc_cubic", "fd_weighted")]:
        out = run([SDF_EVAL, path, str(tmp_path / "p.npy"), "--interpolator", interpolator,
                   "--derivatives", derivatives]).stdout
        ref = np.loadtxt(out.splitlines())
        values, gradients = sl.read_field(path).reconstruct(p, interpolator=interpolator, derivatives=derivatives)
        # sdf-eval prints %.9g: 9 significant digits, a relative error up to 5e-9.
        assert np.allclose(values, ref[:, 0], rtol=6e-9, atol=1e-15)
        assert np.allclose(gradients, ref[:, 1:], rtol=6e-9, atol=6e-9)


def test_trilinear_reconstruction_interpolates_the_samples(box):
    f = sl.sample(box, lattice="cc", resolution=(6, 6, 6), backend="cpu", precision="double")
    o, h = np.array(f.origin), f.spacing
    idx = np.array([[1, 2, 3], [4, 4, 1], [0, 5, 2]])
    values, _ = f.reconstruct(o + h * idx, interpolator="trilinear")
    assert np.allclose(values, [f.values[k, j, i] for i, j, k in idx], atol=1e-13)
    with pytest.raises(ValueError, match="bcc_cubic"):
        f.reconstruct(np.zeros((1, 3)), interpolator="bcc_cubic")


def test_render_returns_a_shaded_image(box):
    f = sl.sample(box, lattice="cc", resolution=12, backend="cpu")
    image = sl.render(f, size=(48, 32), backend="cpu", mesh=box)
    assert image.shape == (32, 48, 3) and image.dtype == np.float32
    assert 0 <= image.min() and image.max() <= 1
    centre, corner = image[16, 24], image[0, 0]
    assert not np.allclose(centre, corner)  # the box is hit in the middle, not in the corner
    with pytest.raises(ValueError, match=r"render\(\): key 'render.views\[0\]': unknown view \"nowhere\""):
        sl.render(f, view="nowhere")
    # The arguments are read by the configs' render codec: its checks and messages.
    with pytest.raises(ValueError, match=r"render\(\): key 'render.size': expected \[width, height\] with entries in 1..16384"):
        sl.render(f, size=(0, 32))
    with pytest.raises(ValueError, match=r"render\(\): key 'render.fov': expected a vertical field of view in degrees in \(0, 180\)"):
        sl.render(f, eye=(3, 2, 1), target=(0, 0, 0), fov=180)


def test_version_matches_the_tools():
    # The commit itself is compared only in form: the tools and the module may have been
    # built at different commits of one build tree (each target rebuilds on its own).
    out = run([SDF_QUERY, "--version"]).stdout.strip()
    assert out.startswith(f"sdf-query {sl.__version__} (commit ")
    assert sl.build_commit == "unknown" or (len(sl.build_commit) == 40 and int(sl.build_commit, 16) >= 0)


@pytest.mark.skipif("SDF_BUILD_DIR" not in os.environ, reason="needs the build directory (CTest passes it)")
def test_cmake_install_puts_an_importable_module(tmp_path):
    prefix = tmp_path / "prefix"
    run([os.environ.get("CMAKE_COMMAND", "cmake"), "--install", os.environ["SDF_BUILD_DIR"], "--prefix", str(prefix)])
    site = prefix / os.environ["SDF_PYTHON_INSTALL_DIR"]
    env = dict(os.environ, PYTHONPATH=str(site))
    r = subprocess.run([sys.executable, "-c", "import sdf_lattices as s; print(s.__file__); print(s.__version__)"],
                       capture_output=True, text=True, env=env, cwd=str(tmp_path))
    assert r.returncode == 0, r.stderr
    where, version = r.stdout.split()
    assert where.startswith(str(site)) and version == sl.__version__


def test_docstrings_everywhere():
    for name in ["load_mesh", "query", "sample", "read_field", "render", "Mesh", "Field", "QueryResult"]:
        assert len(getattr(sl, name).__doc__ or "") > 40, name
    for cls in (sl.Mesh, sl.Field, sl.QueryResult):
        for attr, value in vars(cls).items():
            if not attr.startswith("_"):
                assert (value.__doc__ or "").strip(), f"{cls.__name__}.{attr}"


def test_sample_refuses_a_lattice_beyond_the_available_memory(box, monkeypatch):
    """sample() has run-experiment's memory plan: refused up front, with the figures (issue 26)."""
    monkeypatch.setenv("SDF_MEMORY_AVAILABLE", str(600 << 20))
    with pytest.raises(RuntimeError, match=r"sample\(\): sampling box on 400x400x400 .* needs about .* available"):
        sl.sample(box, resolution=400, backend="cpu")
    assert sl.sample(box, resolution=8, backend="cpu").num_points == 512  # a lattice that fits
