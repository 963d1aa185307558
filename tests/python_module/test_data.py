"""sdf_lattices.data (ML training data) against independent truth: a box's exact signed distance
and gradient (Quilez's formula), a scalar transcription of core/sampling/point_sets.cpp's
generator, the point groups' statistics, and query() on the original mesh for normalisation.
"""
import math
import os

import numpy as np
import pytest

import sdf_lattices as sl
from sdf_lattices import data

HALF = np.array([1.0, 0.5, 0.25])   # the box's half extents: faces of areas 2, 4 and 8 (twice each)


def box_mesh(half=HALF, skip_face=None):
    corners = np.array([[(-1) ** (1 - ((c >> k) & 1)) for k in range(3)] for c in range(8)], dtype=float)
    quads = [(1, 3, 7, 5), (0, 4, 6, 2), (2, 6, 7, 3), (0, 1, 5, 4), (4, 5, 7, 6), (0, 2, 3, 1)]
    faces = []
    for f, (a, b, c, d) in enumerate(quads):
        if f != skip_face:
            faces += [(a, b, c), (a, c, d)]
    return sl.Mesh(corners * half, np.array(faces, dtype=np.int64), name="box")


def box_sdf(p, half):
    """Exact signed distance and unit gradient of an axis-aligned box centred at the origin."""
    q = np.abs(p) - half
    outside = np.maximum(q, 0.0)
    out_len = np.linalg.norm(outside, axis=1)
    d = out_len + np.minimum(q.max(axis=1), 0.0)
    g = np.zeros_like(p)
    g[np.arange(len(p)), q.argmax(axis=1)] = 1.0
    g = np.where((out_len > 0)[:, None], outside / np.where(out_len > 0, out_len, 1)[:, None], g) * np.sign(p)
    return d, g


class ScalarSplitMix64:
    """core/sampling/point_sets.cpp's generator, transcribed with Python integers."""
    M = (1 << 64) - 1

    def __init__(self, seed):
        self.state = seed

    def next(self):
        self.state = (self.state + 0x9E3779B97F4A7C15) & self.M
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & self.M
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & self.M
        return z ^ (z >> 31)

    def uniform(self):
        return (self.next() >> 11) * 2.0 ** -53

    def normal(self):
        u1 = 1.0 - self.uniform()
        u2 = self.uniform()
        return math.sqrt(-2.0 * math.log(u1)) * math.cos(6.283185307179586 * u2)


@pytest.fixture(scope="module")
def box():
    return box_mesh()


# ---- the generator ----------------------------------------------------------------------------

def test_uniform_box_draws_the_cpp_stream():
    rng = ScalarSplitMix64(12345)
    expected = np.array([[rng.uniform() for _ in range(3)] for _ in range(50)])
    lo, hi = np.array([-1.0, 0.0, 2.0]), np.array([1.0, 3.0, 2.5])
    got = data.uniform_box(lo, hi, 50, 12345)
    assert np.array_equal(got, lo + expected * (hi - lo))   # every bit


def test_surface_points_draw_the_cpp_stream(box):
    v, t = box.vertices, box.faces
    got, tri = data.surface_gaussian(v, t, 40, 0.1, 777)
    areas = [0.5 * np.linalg.norm(np.cross(v[b] - v[a], v[c] - v[a])) for a, b, c in t]
    cumulative = np.cumsum(areas)
    rng = ScalarSplitMix64(777)
    for p, i_got in zip(got, tri):
        pick = rng.uniform() * cumulative[-1]
        i = min(int(np.searchsorted(cumulative, pick, side="right")), len(t) - 1)
        s, r = rng.uniform(), rng.uniform()
        if s + r > 1:
            s, r = 1 - s, 1 - r
        a, b, c = v[t[i]]
        o = np.array([rng.normal(), rng.normal(), rng.normal()])
        assert i_got == i
        np.testing.assert_allclose(p, a + (b - a) * s + (c - a) * r + o * 0.1, rtol=0, atol=1e-15)


def test_surface_points_are_area_weighted_and_gaussian(box):
    v, t = box.vertices, box.faces
    n, sigma = 200_000, 0.03
    on, tri_on = data.surface_gaussian(v, t, n, 0.0, 5)
    off, tri_off = data.surface_gaussian(v, t, n, sigma, 5)
    assert np.array_equal(tri_on, tri_off)            # the same triangles and barycentrics ...
    offset = off - on                                  # ... so the difference is the offset alone
    assert abs(offset.mean()) < 5 * sigma / math.sqrt(3 * n)
    assert offset.std() == pytest.approx(sigma, rel=0.01)
    # On the box's faces (|d| = 0), in proportion to their areas 2 : 4 : 8.
    d, _ = box_sdf(on, HALF)
    assert np.abs(d).max() < 1e-15
    axis = np.argmax(np.abs(on) / HALF, axis=1)       # the face each point is on
    share = np.bincount(axis, minlength=3) / n
    np.testing.assert_allclose(share, [2 / 14, 4 / 14, 8 / 14], atol=5 * math.sqrt(0.25 / n))


def test_uniform_points_are_uniform():
    p = data.uniform_box((-1, -2, 0), (1, 2, 1), 100_000, 3)
    assert p.min(axis=0).tolist() >= [-1, -2, 0] and np.all(p.max(axis=0) < [1, 2, 1])
    np.testing.assert_allclose(p.mean(axis=0), [0, 0, 0.5], atol=0.02)
    np.testing.assert_allclose(p.var(axis=0), np.array([2, 4, 1]) ** 2 / 12, rtol=0.02)


# ---- normalisation ------------------------------------------------------------------------------

def test_normalize_to_unit_cube_centres_and_scales(box):
    unit, norm = data.normalize_to_unit_cube(box, padding=0.05)
    lo, hi = np.array(unit.bounds)
    np.testing.assert_allclose(lo + hi, 0, atol=1e-15)
    assert (hi - lo).max() == pytest.approx(0.9)
    assert norm.scale == pytest.approx(2.0 / 0.9)
    np.testing.assert_allclose(unit.vertices * norm.scale + norm.center, box.vertices, atol=1e-15)
    assert np.array_equal(unit.faces, box.faces)


def test_normalized_distances_scale_back_to_the_original(box):
    s = data.sample_near_surface(box, 2000, seed=4)
    world = s.points * s.scale + s.center
    original = sl.query(box, world)
    np.testing.assert_allclose(s.sdf * s.scale, original.distance, rtol=0, atol=1e-12)


# ---- samples -------------------------------------------------------------------------------------

def test_samples_have_the_box_exact_values(box):
    s = data.sample_near_surface(box, 30_000, surface_fraction=0.1, seed=11)
    half = HALF / 2.0                                 # the normalised box: largest side 1
    d, g = box_sdf(s.points, half)
    near = s.group != 0
    np.testing.assert_allclose(s.sdf[near], d[near], rtol=0, atol=1e-12)
    assert np.array_equal(s.occupancy, s.sdf < 0) and 0.2 < s.occupancy[near].mean() < 0.8
    # Gradients: exact where one feature is nearest (not on the box's medial surfaces).
    q = np.sort(np.abs(s.points) - half, axis=1)
    clear = near & (np.abs(q[:, 2] - q[:, 1]) > 1e-6)
    np.testing.assert_allclose(s.normals[clear], g[clear], rtol=0, atol=1e-9)
    # On-surface points: distance 0 to rounding, the face's outward normal.
    on = s.group == 0
    assert np.abs(s.sdf[on]).max() < 1e-14
    face = np.argmax(np.abs(s.points[on]) / half, axis=1)
    expected = np.zeros((on.sum(), 3))
    expected[np.arange(on.sum()), face] = np.sign(s.points[on][np.arange(on.sum()), face])
    np.testing.assert_allclose(s.normals[on], expected, atol=1e-15)


def test_groups_counts_and_box():
    s = data.sample_near_surface("shape:torus", 10_001, sigmas=(0.05, 0.01, 0.001), uniform_fraction=0.1,
                                 surface_fraction=0.2, margin=0.25, seed=2)
    assert s.groups == ("surface", "gaussian(sigma=0.05)", "gaussian(sigma=0.01)", "gaussian(sigma=0.001)", "uniform")
    counts = np.bincount(s.group, minlength=5).tolist()
    assert counts == [2000, 2334, 2334, 2333, 1000] and len(s) == 10_001
    u = s.points[s.group == 4]
    assert np.all(np.abs(u) <= 0.75) and np.abs(u).max() > 0.7
    # Farther groups lie farther from the surface: mean |d| ~ sigma * sqrt(2 / pi) for a flat surface.
    for g, sigma in ((1, 0.05), (2, 0.01), (3, 0.001)):
        assert np.mean(np.abs(s.sdf[s.group == g])) == pytest.approx(sigma * math.sqrt(2 / math.pi), rel=0.15)


def test_the_same_seed_gives_the_same_samples(box):
    a = data.sample_near_surface(box, 5000, seed=9)
    b = data.sample_near_surface(box, 5000, seed=9)
    c = data.sample_near_surface(box, 5000, seed=10)
    for name in data.Samples.ARRAYS:
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert not np.array_equal(a.points, c.points)


def test_float32_points_get_their_own_exact_values(box):
    s = data.sample_near_surface(box, 3000, dtype="float32", seed=1)
    assert s.points.dtype == np.float32 and s.sdf.dtype == np.float32
    d, _ = box_sdf(s.points.astype(np.float64), HALF / 2.0)
    np.testing.assert_allclose(s.sdf, d.astype(np.float32), rtol=0, atol=1e-7)


@pytest.mark.filterwarnings("ignore::sdf_lattices.MeshWarning", "ignore::sdf_lattices.SdfWarning")
def test_open_mesh_signs_by_winding_number():
    open_box = box_mesh(skip_face=0)                   # no +x face: pseudonormal signs fail there
    s = data.sample_near_surface(open_box, 4000, seed=3)
    d, _ = box_sdf(s.points, HALF / 2.0)
    deep = np.abs(d) > 0.02
    assert np.array_equal(s.occupancy[deep], d[deep] < 0)


def test_batch_equals_single_calls(box):
    b = data.sample_batch([box, "shape:sphere"], 1000, seed=20, sigmas=(0.01,))
    assert b.points.shape == (2, 1000, 3) and b.sdf.shape == (2, 1000) and b.center.shape == (2, 3)
    for i, mesh in enumerate([box, "shape:sphere"]):
        one = data.sample_near_surface(mesh, 1000, seed=20 + i, sigmas=(0.01,))
        for name in data.Samples.ARRAYS:
            assert np.array_equal(getattr(b, name)[i], getattr(one, name)), name


def test_save_writes_npz_atomically(box, tmp_path):
    s = data.sample_near_surface(box, 500, seed=1)
    path = tmp_path / "box.npz"
    s.save(path)
    with np.load(path) as f:
        assert np.array_equal(f["sdf"], s.sdf) and list(f["groups"]) == list(s.groups)
    with pytest.raises(ValueError, match="exists"):
        s.save(path)
    s.save(path, overwrite=True)
    assert os.listdir(tmp_path) == ["box.npz"]


@pytest.mark.parametrize("kwargs, message", [
    ({"count": -1}, "count"), ({"count": 2.5}, "count"), ({"seed": -1}, "seed"), ({"seed": 2 ** 64}, "seed"),
    ({"sigmas": (0.01, -1.0)}, "sigmas"), ({"sigmas": ()}, "sigmas"), ({"uniform_fraction": 1.5}, "uniform_fraction"),
    ({"uniform_fraction": 0.6, "surface_fraction": 0.6}, "surface_fraction"), ({"padding": 0.5}, "padding"),
    ({"dtype": "int8"}, "dtype"), ({"box": ((0, 0, 0), (1, 1, 0))}, "box"),
])
def test_bad_arguments_raise_value_error(box, kwargs, message):
    args = dict(count=100)
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        data.sample_near_surface(box, **args)


def test_bad_mesh_arguments():
    with pytest.raises(TypeError, match="mesh"):
        data.sample_near_surface(42, 10)
    with pytest.raises((ValueError, RuntimeError), match="no_such_mesh.obj"):
        data.sample_near_surface("no_such_mesh.obj", 10)
    with pytest.raises(ValueError, match="at least one"):
        data.sample_batch([], 10)
