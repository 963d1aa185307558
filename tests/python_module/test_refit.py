"""SDF.refit of a deforming mesh (issue 39 item 4): the topology of the first preparation
(welds, dropped triangles, edge adjacency, shells) is kept and only the geometry is made
again (core/mesh/prepared_mesh.h, refit_prepared_mesh). Truth is a freshly built SDF of the
moved vertices: distance, sign, triangle, gradient, closest point, barycentric coordinates,
winding numbers and the prepared mesh itself, bit for bit, on several deformations and
sampler options; and the refusals where the new positions would weld or drop otherwise,
each naming the vertex or triangle. No torch needed (test_training.py has the vertex
gradients through a refit).
"""
import numpy as np
import pytest

import sdf_lattices as sl
from test_sdf_lattices import box_arrays, same_bits


def _deformations(v):
    c, s = np.cos(0.7), np.sin(0.7)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    yield "scale and shift", v * 1.25 + np.array([0.125, -0.5, 2.0])
    yield "rotation", v @ rotation.T
    yield "wave", v + 0.05 * np.sin(3.0 * v[:, [1, 2, 0]])
    yield "bend", np.c_[2.0 * v[:, 0], 0.5 * v[:, 1], v[:, 2] + 0.3 * v[:, 0] ** 2]
    yield "jitter", v + 1e-3 * np.sin(97.0 * v + np.array([0.1, 0.2, 0.3]))


def _soup(v, f):
    """Every triangle's corners written out on their own: preparation welds them back."""
    return v[f].reshape(-1, 3), np.arange(3 * len(f), dtype=np.int64).reshape(-1, 3)


def _expect_same(refitted, fresh, p, what):
    a, b = refitted.query(p, winding=True), fresh.query(p, winding=True)
    for name in ("distance", "gradient", "triangle", "closest_point", "barycentric", "winding", "winding_error_bound"):
        assert same_bits(getattr(a, name), getattr(b, name)), f"{what}: {name}"
    assert (refitted.sign, refitted.sign_reason, refitted.sampler) == (fresh.sign, fresh.sign_reason, fresh.sampler), what
    m, n = refitted.mesh, fresh.mesh
    for name in ("vertices", "faces", "source_triangle", "input_vertices", "input_faces"):
        assert same_bits(getattr(m, name), getattr(n, name)), f"{what}: mesh.{name}"
    assert (m.sha256, m.bounds, m.report, m.warnings) == (n.sha256, n.bounds, n.report, n.warnings), what


@pytest.mark.parametrize("sampler", [{}, {"sign": "winding"}, {"precision": "double"}, {"sign": "none"},
                                     {"method": "brute_force"}])
def test_refit_equals_a_fresh_sdf_bit_for_bit(sampler):
    m = sl.load_mesh("shape:torus")
    for soup in (False, True):
        # A soup's copies of a corner are moved as one (the deformation of the welded vertex):
        # NumPy need not round equal inputs equally at every position of an array.
        v, f = _soup(m.input_vertices, m.input_faces) if soup else (m.input_vertices, m.input_faces)
        p = np.random.default_rng(9).uniform(-1.7, 1.7, (2000, 3))
        bound = sl.SDF(sl.Mesh(v, f), backend="cpu", **sampler)
        before = bound.query(p)
        for name, moved in _deformations(m.input_vertices):  # each refit from the last one
            if soup:
                moved = _soup(moved, m.input_faces)[0]
            refitted = bound.refit(moved)
            _expect_same(refitted, sl.SDF(sl.Mesh(moved, f), backend="cpu", **sampler), p, f"{name} {sampler}")
            bound = refitted
        # the first SDF and its results are untouched
        assert same_bits(sl.SDF(sl.Mesh(v, f), backend="cpu", **sampler).query(p).distance, before.distance)


def test_refit_follows_self_intersections_into_the_sign():
    """A deformation that makes the torus pass through itself: auto's sign turns to the
    winding number's, as for a fresh SDF, and back."""
    m = sl.load_mesh("shape:torus")
    v, f = m.input_vertices, m.input_faces
    rho = np.linalg.norm(v[:, :2], axis=1)
    through = v.copy()
    through[:, :2] *= ((rho - 0.9) / rho)[:, None]  # the inner half moved across the axis
    bound = sl.SDF(sl.Mesh(v, f), backend="cpu")
    assert bound.sign == "pseudonormal"
    p = np.random.default_rng(4).uniform(-1.5, 1.5, (2000, 3))
    with pytest.warns(sl.MeshWarning, match="intersects itself"):
        crossed = bound.refit(through)
    with pytest.warns(sl.MeshWarning, match="intersects itself"):
        fresh = sl.SDF(sl.Mesh(through, f), backend="cpu")
    assert fresh.mesh.report["self_intersecting_pairs"] > 0 and fresh.sign == "winding"
    _expect_same(crossed, fresh, p, "self-intersecting")
    _expect_same(crossed.refit(v), sl.SDF(sl.Mesh(v, f), backend="cpu"), p, "back")


def test_refit_follows_the_outward_flip():
    v, f = box_arrays()
    bound = sl.SDF(sl.Mesh(v, f), backend="cpu")
    inward = v * np.array([-1.0, 1.0, 1.0])  # mirrored: oriented inward, which preparation flips
    with pytest.warns(sl.MeshWarning, match="flipped"):
        flipped = bound.refit(inward)
    with pytest.warns(sl.MeshWarning, match="flipped"):
        fresh = sl.SDF(sl.Mesh(inward, f), backend="cpu")
    assert flipped.mesh.orientation == "outward (flipped from inward)"
    p = np.random.default_rng(5).uniform(-2, 2, (500, 3))
    _expect_same(flipped, fresh, p, "flipped")
    _expect_same(flipped.refit(v), bound, p, "flipped back")


def test_refit_keeps_the_weld_tolerance():
    v, f = box_arrays()
    bound = sl.SDF(sl.Mesh(v, f, weld_tolerance=1e-3), backend="cpu")
    assert same_bits(bound.refit(v * 2).query([[3.0, 0, 0]]).distance, np.array([1.0]))
    sv, sf = _soup(v, f)
    sv = sv + np.random.default_rng(6).uniform(-1e-5, 1e-5, sv.shape)  # copies of a corner 2e-5 apart at most
    bound = sl.SDF(sl.Mesh(sv, sf, weld_tolerance=1e-4), backend="cpu")
    assert bound.mesh.report["welded_vertices"] == len(sv) - 8
    p = np.random.default_rng(7).uniform(-2, 2, (500, 3))
    _expect_same(bound.refit(sv * 1.5), sl.SDF(sl.Mesh(sv * 1.5, sf, weld_tolerance=1e-4), backend="cpu"), p, "tolerance")


def test_refit_refuses_positions_that_weld_or_drop_otherwise():
    v, f = box_arrays()
    sv, sf = _soup(v, f)
    soup = sl.SDF(sl.Mesh(sv, sf), backend="cpu")
    copy = next(i for i in range(1, len(sv)) if (sv[:i] == sv[i]).all(1).any())
    first = int(np.flatnonzero((sv[:copy] == sv[copy]).all(1))[0])
    apart = sv.copy()
    apart[copy, 0] += 1e-3
    with pytest.raises(ValueError, match=f"input vertex {copy} was welded to input vertex {first} when the mesh was "
                                         "prepared and is a vertex of its own at the new positions"):
        soup.refit(apart)
    box = sl.SDF(sl.Mesh(v, f), backend="cpu")
    collapsed = v.copy()
    collapsed[7] = collapsed[5]  # two corners on one another: a new weld (and two triangles degenerate)
    with pytest.raises(ValueError, match="input vertex 7 was a vertex of its own when the mesh was prepared and is "
                                         "welded to input vertex 5 .*prepare the moved mesh anew"):
        box.refit(collapsed)
    flat = v.copy()
    a, b, c = f[3]
    flat[c] = 0.5 * (v[a] + v[b])  # a corner on the line of its triangle's other two
    with pytest.raises(ValueError, match="is degenerate \\(collinear corners\\) at the new positions and was not"):
        box.refit(flat)
    with pytest.raises(ValueError, match="expected 8 rows"):
        box.refit(v[:7])
    # The refusals leave the SDF as it was.
    assert same_bits(box.refit(v).query([[3.0, 0, 0]]).distance, box.query([[3.0, 0, 0]]).distance)

