"""Training-loop features (issue 39 item 4): torch autograd on the CPU (and CUDA where present)
with respect to the points and the mesh's vertices, SDF.refit's vertex gradients, a batch
of meshes in one call, and float32 outputs.

Truth is independent of the code under test: central finite differences of the distance in
float64 (the distance itself being checked against analytic truth elsewhere), the box's
analytic closest features (corner, edge, face: the derivative with respect to a corner is
-weight * gradient), a freshly built SDF for refit, per-mesh queries for the batch, and
NumPy's rounding of the float64 results for float32. CUDA tests skip without a GPU.
"""
import numpy as np
import pytest

import sdf_lattices as sl
from sdf_lattices import _torch
from test_sdf_lattices import HALF, box_arrays, same_bits

torch = pytest.importorskip("torch", reason="PyTorch (Debian python3-torch) is not installed")

H = 1e-6  # central differences: error ~ h^2 * curvature + eps * |d| / h, far below the tolerances


def _cuda():
    return torch.cuda.is_available() and sl.cuda_available()


@pytest.fixture(scope="module")
def torus_arrays():
    m = sl.load_mesh("shape:torus")
    return m.input_vertices, m.input_faces


def _smooth_points(vertices, faces, n, seed, step=1e-4, **sampler):
    """n points around the mesh whose gradient does not change within `step` along any axis:
    away from the medial axis, where the distance is differentiable and the stencils of the
    finite differences below stay on one closest feature."""
    rng = np.random.default_rng(seed)
    lo, hi = vertices.min(0) - 0.3, vertices.max(0) + 0.3
    p = rng.uniform(lo, hi, size=(4 * n, 3))
    g = sl.query((vertices, faces), p, **sampler).gradient
    keep = np.ones(len(p), bool)
    for k in range(3):
        for s in (-step, step):
            q = p.copy()
            q[:, k] += s
            keep &= np.abs(sl.query((vertices, faces), q, **sampler).gradient - g).max(1) < 1e-3
    return p[keep][:n]


# ---- autograd with respect to the points ------------------------------------------------------

def test_cpu_points_gradient_equals_central_differences(torus_arrays):
    v, f = torus_arrays
    p = _smooth_points(v, f, 300, seed=1)
    assert len(p) == 300
    weights = np.random.default_rng(2).uniform(0.5, 2.0, len(p))
    points = torch.tensor(p, requires_grad=True)
    d = sl.sdf((v, f), points, differentiable=True)
    assert isinstance(d, torch.Tensor) and d.requires_grad and d.dtype == torch.float64
    assert same_bits(d.detach().numpy(), sl.sdf((v, f), p))
    (torch.tensor(weights) * d).sum().backward()
    fd = np.empty_like(p)
    for k in range(3):
        e = np.zeros(3)
        e[k] = H
        fd[:, k] = (sl.sdf((v, f), p + e) - sl.sdf((v, f), p - e)) / (2 * H)
    assert np.abs(points.grad.numpy() - weights[:, None] * fd).max() < 1e-6
    # and it is the query's exact gradient itself
    assert np.array_equal(points.grad.numpy(), weights[:, None] * sl.query((v, f), p).gradient)


def test_cpu_tensor_points_that_require_grad_are_read_without_differentiable(torus_arrays):
    v, f = torus_arrays
    p = np.random.default_rng(3).uniform(-1.5, 1.5, (50, 3))
    points = torch.tensor(p, requires_grad=True)
    bound = sl.SDF((v, f))
    r = bound.query(points)  # was a misleading TypeError
    assert isinstance(r, sl.QueryResult) and same_bits(r.distance, bound.query(p).distance)
    r = bound.query(points, differentiable=True)
    assert isinstance(r, sl.DeviceQueryResult)
    assert same_bits(r.distance.detach().numpy(), bound.query(p).distance)
    assert same_bits(r.gradient.numpy(), bound.query(p).gradient) and np.array_equal(r.triangle.numpy(), bound.query(p).triangle)
    r = bound.query(torch.tensor(p.astype(np.float32), requires_grad=True), differentiable=True)
    r.distance.sum().backward()  # float32 points get float32 gradients
    with pytest.raises(TypeError, match="torch tensor"):
        bound.query(p, differentiable=True)
    with pytest.raises(ValueError, match="winding"):
        bound.query(points, differentiable=True, winding=True)


def test_unsigned_distance_points_gradient(torus_arrays):
    v, f = torus_arrays
    p = _smooth_points(v, f, 100, seed=4, sign="none")
    points = torch.tensor(p, requires_grad=True)
    d = sl.sdf((v, f), points, differentiable=True, sign="none")
    assert (d.detach().numpy() >= 0).all()
    d.sum().backward()
    fd = np.stack([(sl.sdf((v, f), p + e, sign="none") - sl.sdf((v, f), p - e, sign="none")) / (2 * H)
                   for e in np.eye(3) * H], axis=1)
    assert np.abs(points.grad.numpy() - fd).max() < 1e-6


# ---- autograd with respect to the vertices ----------------------------------------------------

def _box_vertex_gradient(p):
    v, f = box_arrays()
    vertices = torch.tensor(v, requires_grad=True)
    d = sl.sdf((vertices, f), torch.tensor(p), differentiable=True)
    d.backward(torch.ones_like(d))
    return d.detach().numpy(), vertices.grad.numpy()


@pytest.mark.parametrize("point, expected_d, corner_weights, gradient", [
    # outside a corner: the closest point is vertex 7 = (1, .5, .25) itself (weight 1)
    ((1.5, 1.0, 0.6), np.linalg.norm([0.5, 0.5, 0.35]), {7: 1.0}, np.array([0.5, 0.5, 0.35]) / np.linalg.norm([0.5, 0.5, 0.35])),
    # outside the edge x = 1, y = .5 between vertices 3 (z = -.25) and 7 (z = .25), at z = .1
    ((1.4, 0.9, 0.1), np.hypot(0.4, 0.4), {3: 0.3, 7: 0.7}, np.array([1.0, 1.0, 0.0]) / np.sqrt(2)),
    # outside the face x = 1, inside its triangle (1, 7, 5): weights (0.2, 0.3, 0.5)
    ((1.3, -0.2, 0.15), 0.3, {1: 0.2, 7: 0.3, 5: 0.5}, np.array([1.0, 0.0, 0.0])),
    # inside, nearest that face: d < 0, the gradient still outward
    ((0.9, -0.2, 0.05), -0.1, {1: 0.4, 7: 0.3, 5: 0.3}, np.array([1.0, 0.0, 0.0])),
])
def test_box_vertex_gradient_on_corner_edge_and_face(point, expected_d, corner_weights, gradient):
    """d d / d V_k = -b_k * grad_p d on the closest feature's corners, zero elsewhere: exact truth
    from the box's geometry, and central differences of rebuilt meshes."""
    p = np.array([point]) * 1.0
    d, grad = _box_vertex_gradient(p)
    assert abs(d[0] - expected_d) < 1e-12
    expected = np.zeros((8, 3))
    for k, b in corner_weights.items():
        expected[k] = -b * gradient
    assert np.abs(grad - expected).max() < 1e-12
    v, f = box_arrays()
    fd = np.zeros((8, 3))
    for row in range(8):
        for k in range(3):
            up, down = v.copy(), v.copy()
            up[row, k] += H
            down[row, k] -= H
            fd[row, k] = (sl.sdf((up, f), p)[0] - sl.sdf((down, f), p)[0]) / (2 * H)
    assert np.abs(grad - fd).max() < 1e-6


def test_torus_vertex_gradient_equals_central_differences(torus_arrays):
    v, f = torus_arrays
    p = _smooth_points(v, f, 200, seed=5)
    w = np.random.default_rng(6).uniform(0.5, 2.0, len(p))
    vertices = torch.tensor(v, requires_grad=True)
    points = torch.tensor(p, requires_grad=True)
    bound = sl.SDF((vertices, f))
    r = bound.query(points, differentiable=True)
    (torch.tensor(w) * r.distance).sum().backward()
    grad = vertices.grad.numpy()
    assert np.abs(points.grad.numpy() - w[:, None] * r.gradient.numpy()).max() == 0
    touched = np.flatnonzero(np.abs(grad).max(1) > 0)
    untouched = np.flatnonzero(np.abs(grad).max(1) == 0)
    assert len(touched) > 20 and len(untouched) > 0
    rows = np.concatenate([np.random.default_rng(7).choice(touched, 8, replace=False), untouched[:2]])
    for row in rows:
        for k in range(3):
            up, down = v.copy(), v.copy()
            up[row, k] += H
            down[row, k] -= H
            fd = (np.dot(w, sl.sdf((up, f), p)) - np.dot(w, sl.sdf((down, f), p))) / (2 * H)
            assert abs(grad[row, k] - fd) < 1e-5 * max(1.0, abs(fd)), (row, k, grad[row, k], fd)


def test_vertex_gradient_lands_on_the_callers_rows_through_welding():
    """Duplicated input vertices (welded by the preparation): each face's own rows get its
    share, in the caller's numbering."""
    v, f = box_arrays()
    dup = np.vstack([v, v[7:8]])  # row 8 = a copy of vertex 7, used by one face
    f2 = f.copy()
    uses = np.argwhere(f2 == 7)
    f2[uses[0][0], uses[0][1]] = 8
    vertices = torch.tensor(dup, requires_grad=True)
    p = np.array([[1.5, 1.0, 0.6]])
    d = sl.sdf((vertices, f2), torch.tensor(p), differentiable=True)
    d.sum().backward()
    g = vertices.grad.numpy()
    corner = np.array([0.5, 0.5, 0.35]) / np.linalg.norm([0.5, 0.5, 0.35])
    # the corner's whole derivative goes to row 7 or row 8 (whichever face was closest)
    assert np.abs(g[7] + g[8] + corner).max() < 1e-12 and np.abs(g[:7]).max() == 0


def test_barycentric_of_matches_the_querys_weights(torus_arrays):
    """The GPU path's weights (computed on the device from c = p - d * g) checked on the CPU
    against the query's own barycentric coordinates."""
    v, f = torus_arrays
    p = np.random.default_rng(8).uniform(-1.6, 1.6, (2000, 3))
    r = sl.query((v, f), p)
    corners = f[r.triangle]
    closest = torch.tensor(p) - torch.tensor(r.distance)[:, None] * torch.tensor(r.gradient)
    w = _torch.barycentric_of(closest, *(torch.tensor(v[corners[:, k]]) for k in range(3))).numpy()
    assert np.abs(w - r.barycentric).max() < 1e-9


def test_vertex_gradient_with_weights_computed_as_on_a_gpu(torus_arrays):
    """The GPU path (no barycentric from the query: computed from c = p - d * g) run on the CPU:
    the same vertex gradients as with the query's weights, to rounding."""
    v, f = torus_arrays
    p = _smooth_points(v, f, 300, seed=16)
    vertices = torch.tensor(v, requires_grad=True)
    bound = sl.SDF((vertices, f))
    r = bound.query(p)
    grads = []
    for weights in (torch.tensor(r.barycentric), None):
        vertices.grad = None
        d = _torch.differentiable_distance(bound, torch.tensor(p), torch.tensor(r.distance), torch.tensor(r.gradient),
                                           torch.tensor(r.triangle), weights)
        d.sum().backward()
        grads.append(vertices.grad.numpy().copy())
    assert np.abs(grads[0]).max() > 0.1 and np.abs(grads[0] - grads[1]).max() < 1e-9


# ---- refit ---------------------------------------------------------------------------------------

def _deformed(v, t):
    return v * (1.0 + 0.1 * t) + 0.05 * np.sin(3.0 * v[:, [1, 2, 0]] + t)


# (refit against a fresh SDF, and its refusals: test_refit.py, which needs no torch)


def test_refit_with_torch_vertices_gives_vertex_gradients(torus_arrays):
    v, f = torus_arrays
    moved = torch.tensor(_deformed(v, 0.3), requires_grad=True)
    refitted = sl.SDF((v, f)).refit(moved)
    p = _smooth_points(moved.detach().numpy(), f, 20, seed=10)
    d = refitted.query(torch.tensor(p), differentiable=True).distance
    d.sum().backward()
    assert moved.grad is not None and np.abs(moved.grad.numpy()).sum() > 0
    fresh = torch.tensor(moved.detach().numpy(), requires_grad=True)
    sl.sdf((fresh, f), torch.tensor(p), differentiable=True).sum().backward()
    assert np.array_equal(moved.grad.numpy(), fresh.grad.numpy())


# ---- a batch of meshes ----------------------------------------------------------------------

@pytest.fixture(scope="module")
def batch():
    v, f = box_arrays()
    meshes = [sl.load_mesh("shape:torus"), sl.load_mesh("shape:sphere"), sl.Mesh(v, f)]
    sdfs = [sl.SDF(m, backend="cpu") for m in meshes] + [sl.SDF(meshes[0], backend="cpu", sign="none")]
    rng = np.random.default_rng(11)
    points = [rng.uniform(-1.5, 1.5, (n, 3)) for n in (5000, 1, 0, 777)]
    points[3] = points[3].astype(np.float32)
    return sdfs, points


def test_query_batch_equals_per_mesh_queries_bit_for_bit(batch):
    sdfs, points = batch
    results = sl.query_batch(sdfs, points)
    assert len(results) == len(sdfs)
    for s, p, r in zip(sdfs, points, results):
        one = s.query(p)
        for name in ("distance", "gradient", "triangle", "closest_point", "barycentric"):
            assert same_bits(getattr(r, name), getattr(one, name)), name
        assert r.sign == one.sign and r.sampler == one.sampler
    for s, p, r in zip(sdfs, points, sl.query_batch(tuple(sdfs), points, dtype="float32")):
        assert same_bits(r.distance, s.query(p).distance.astype(np.float32))


def test_query_batch_torch_and_errors(batch):
    sdfs, points = batch
    tensors = [torch.tensor(p, requires_grad=True) for p in points]
    results = sl.query_batch(sdfs, tensors, differentiable=True)
    sum(r.distance.sum() for r in results).backward()
    for s, p, t in zip(sdfs, points, tensors):
        assert np.array_equal(t.grad.numpy(), s.query(p).gradient.astype(p.dtype))
    with pytest.raises(ValueError, match="as many point arrays as SDFs"):
        sl.query_batch(sdfs, points[:2])
    with pytest.raises(TypeError, match=r"sdfs\[1\]: expected an sdf_lattices.SDF"):
        sl.query_batch([sdfs[0], "bunny.obj"], points[:2])
    with pytest.raises(TypeError, match="points: expected a list or tuple"):
        sl.query_batch(sdfs[:1], points[0])
    with pytest.raises(ValueError, match=r"points\[1\]: .*shape \(N, 3\)"):
        sl.query_batch(sdfs[:2], [points[0], np.zeros((3, 2))])


@pytest.mark.parametrize("options", [{}, {"surface_fraction": 0.1, "sign": "winding", "precision": "float",
                                      "dtype": "float32"}])
def test_data_sample_batch_through_query_batch_equals_sample_near_surface(options):
    from sdf_lattices import data
    v, f = box_arrays()
    meshes = ["shape:torus", (v, f), "shape:sphere"]
    batch = data.sample_batch(meshes, 3000, seed=30, **options)
    for i, mesh in enumerate(meshes):
        one = data.sample_near_surface(mesh, 3000, seed=30 + i, **options)
        for name in data.Samples.ARRAYS:
            assert same_bits(getattr(batch, name)[i], getattr(one, name)), name


# ---- float32 outputs ------------------------------------------------------------------------

def test_float32_outputs_are_the_float64_results_rounded(torus_arrays):
    v, f = torus_arrays
    p = np.random.default_rng(12).uniform(-1.5, 1.5, (4000, 3))
    bound = sl.SDF((v, f))
    r64, r32 = bound.query(p), bound.query(p, dtype="float32")
    for name in ("distance", "gradient", "closest_point", "barycentric"):
        a, b = getattr(r32, name), getattr(r64, name)
        assert a.dtype == np.float32 and same_bits(a, b.astype(np.float32)), name
    assert same_bits(r32.triangle, r64.triangle)
    assert r32.distance.nbytes * 2 == r64.distance.nbytes
    assert same_bits(sl.sdf((v, f), p, dtype=np.float32), r64.distance.astype(np.float32))
    assert same_bits(sl.query((v, f), p, dtype="float32").gradient, r64.gradient.astype(np.float32))
    points = torch.tensor(p, requires_grad=True)
    t = bound.query(points, differentiable=True, dtype="float32")
    assert t.distance.dtype == torch.float32 and t.gradient.dtype == torch.float32
    assert same_bits(t.distance.detach().numpy(), r64.distance.astype(np.float32))
    t.distance.sum().backward()
    assert same_bits(points.grad.numpy(), r64.gradient)  # the gradient is computed in double
    with pytest.raises(ValueError, match='dtype: expected "float64" or "float32"'):
        bound.query(p, dtype="float16")
    with pytest.raises(ValueError, match='dtype: expected "float64" or "float32"'):
        sl.sdf((v, f), p, dtype="double-ish")


def test_the_gpu_paths_post_processing_on_cpu_tensors(torus_arrays):
    """What the GPU path does with a device query's float64 tensors (unsigned flip, autograd,
    dtype: sdf_lattices._gpu._finish), run on CPU tensors through a stand-in of the device view."""
    import types
    from sdf_lattices import _gpu
    v, f = torus_arrays
    p = _smooth_points(v, f, 50, seed=17)
    view = types.SimpleNamespace(library="torch", cast=lambda a, dtype: a.to(getattr(torch, dtype)), result=lambda a: a)
    for sign in ("auto", "none"):
        vertices = torch.tensor(v, requires_grad=True)
        bound = sl.SDF((vertices, f), sign=sign)
        signed = sl.query((v, f), p)  # the device path's raw output is the signed one
        points = torch.tensor(p, requires_grad=True)
        r = _gpu._finish(bound, view, points, torch.tensor(signed.distance), torch.tensor(signed.gradient),
                         torch.tensor(signed.triangle), True, "float32")
        host = bound.query(p)
        assert r.distance.dtype == torch.float32 and same_bits(r.distance.detach().numpy(), host.distance.astype(np.float32))
        assert same_bits(r.gradient.numpy(), host.gradient.astype(np.float32))
        r.distance.sum().backward()
        assert same_bits(points.grad.numpy(), host.gradient)
        reference = torch.tensor(v, requires_grad=True)
        sl.sdf((reference, f), torch.tensor(p), differentiable=True, sign=sign).sum().backward()
        assert np.abs(vertices.grad.numpy() - reference.grad.numpy()).max() < 1e-9


# ---- CUDA (skipped without a GPU) -----------------------------------------------------------

cuda = pytest.mark.skipif(not _cuda(), reason="no CUDA device, or no CUDA backend in this build")


@cuda
def test_cuda_autograd_points_and_vertices_equal_the_cpu(torus_arrays):
    v, f = torus_arrays
    p = _smooth_points(v, f, 500, seed=13)
    w = np.random.default_rng(14).uniform(0.5, 2.0, len(p))
    grads = {}
    for device in ("cpu", "cuda"):
        vertices = torch.tensor(v, device=device, requires_grad=True)
        points = torch.tensor(p, device=device, requires_grad=True)
        bound = sl.SDF((vertices, f), backend="cuda")
        r = bound.query(points, differentiable=True)
        assert r.distance.device.type == device
        (torch.tensor(w, device=device) * r.distance).sum().backward()
        grads[device] = (r.distance.detach().cpu().numpy(), points.grad.cpu().numpy(), vertices.grad.cpu().numpy())
    assert same_bits(grads["cpu"][0], grads["cuda"][0]) and same_bits(grads["cpu"][1], grads["cuda"][1])
    # the GPU's barycentric weights are computed from the closest point: equal up to rounding
    assert np.abs(grads["cpu"][2] - grads["cuda"][2]).max() < 1e-9


@cuda
def test_cuda_query_batch_equals_per_mesh_and_float32():
    meshes = [sl.load_mesh("shape:torus"), sl.load_mesh("shape:sphere"), sl.load_mesh("shape:box")]
    sdfs = [sl.SDF(m, backend="cuda") for m in meshes] + [sl.SDF(meshes[0], backend="cuda", sign="none")]
    rng = np.random.default_rng(15)
    points = [torch.tensor(rng.uniform(-1.5, 1.5, (n, 3)), device="cuda") for n in (20000, 1, 0, 999)]
    results = sl.query_batch(sdfs, points)
    for s, p, r in zip(sdfs, points, results):
        one = s.query(p)
        assert torch.equal(r.distance, one.distance) and torch.equal(r.gradient, one.gradient)
        assert torch.equal(r.triangle, one.triangle)
    for s, p, r in zip(sdfs, points, sl.query_batch(sdfs, points, dtype="float32")):
        assert r.distance.dtype == torch.float32 and torch.equal(r.distance, s.query(p).distance.float())
