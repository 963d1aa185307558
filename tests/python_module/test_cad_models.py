"""Sign "auto" on a CAD-like mesh from Python and from sdf-query (issue 22): a box whose planar
faces are fans from their centres over edges split into collinear points, at scales 1e-3 ..
1e3, offsets up to 1e4, axis-aligned and rotated (a rotation with 26-bit entries, so that the
points stay exactly collinear while the orientation determinants round). The report finds no
self-intersection, the mesh is sign-reliable without warnings, and `auto` keeps the
pseudonormal sign, silently, right at points clear of the surface.

Run by CTest (python_module) with PYTHONPATH=build/python and SDF_QUERY set.
"""
import os
import subprocess

import numpy as np
import pytest

import sdf_lattices as sl

SDF_QUERY = os.environ.get("SDF_QUERY", "build/bin/sdf-query")

SIZE = (60, 48, 36)  # grid units; the edges along x, y, z are split into 5, 4 and 3 parts
PARTS = (5, 4, 3)


def rotation(bits):
    """The rotation about (1, 2, 3) by 0.7 radians, its entries rounded to multiples of 2^-bits."""
    a = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    r = np.eye(3) + np.sin(0.7) * k + (1 - np.cos(0.7)) * (k @ k)
    return np.round(r * 2.0**bits) / 2.0**bits


def cad_box_grid():
    """Vertices (grid units) and outward faces: every face a fan from its centre."""
    ids, verts, faces = {}, [], []

    def vid(g):
        if g not in ids:
            ids[g] = len(verts)
            verts.append(g)
        return ids[g]

    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, 1):
            def at(pu, pv):
                g = [0, 0, 0]
                g[axis], g[u], g[v] = side * SIZE[axis], pu, pv
                return tuple(g)
            corners = [(0, 0), (SIZE[u], 0), (SIZE[u], SIZE[v]), (0, SIZE[v])]
            if side == 0:
                corners = corners[:1] + corners[:0:-1]
            ring = []
            for k in range(4):
                (a0, a1), (b0, b1) = corners[k], corners[(k + 1) % 4]
                n = PARTS[u] if a1 == b1 else PARTS[v]
                ring += [vid(at(a0 + (b0 - a0) * j // n, a1 + (b1 - a1) * j // n)) for j in range(n)]
            c = vid(at(SIZE[u] // 2, SIZE[v] // 2))
            faces += [(c, ring[k], ring[(k + 1) % len(ring)]) for k in range(len(ring))]
    return np.array(verts, dtype=float), np.array(faces, dtype=np.int64)


PLACEMENTS = {  # name: (linear map of grid units, offset)
    "axis-aligned 1e-3": (np.eye(3) * 1e-3, np.zeros(3)),
    "axis-aligned 1e3 offset 1e4": (np.eye(3) * 1e3, np.array([1e4, -1e4 / 3, 77.7])),
    "rotated 2^-10 offset 1e4": (rotation(26) * 2.0**-10, np.array([10000.375, -2500.5, 1234.25])),
    "rotated 2^10": (rotation(26) * 2.0**10, np.zeros(3)),
}


def placed(name):
    linear, offset = PLACEMENTS[name]
    grid, faces = cad_box_grid()
    return offset + grid @ linear.T, faces


def points_clear_of_the_surface(name, n=400):
    """Random points (world) at least 1 grid unit from the box's planes, and whether inside."""
    linear, offset = PLACEMENTS[name]
    g = np.random.default_rng(22).uniform(-12, 72, size=(4 * n, 3))
    near = np.zeros(len(g), dtype=bool)
    for k in range(3):
        near |= (np.abs(g[:, k]) < 1) | (np.abs(g[:, k] - SIZE[k]) < 1)
    g = g[~near][:n]
    inside = np.all((g > 0) & (g < np.array(SIZE)), axis=1)
    return offset + g @ linear.T, inside


@pytest.mark.parametrize("name", sorted(PLACEMENTS))
def test_cad_box_is_clean_and_auto_keeps_the_pseudonormal_sign(name):
    vertices, faces = placed(name)
    mesh = sl.Mesh(vertices, faces, name="cad_box")
    assert mesh.report["self_intersecting_pairs"] == 0
    assert mesh.closed and mesh.components == 1 and mesh.sign_reliable
    assert mesh.warnings == []
    points, inside = points_clear_of_the_surface(name)
    assert inside.sum() > 50 and (~inside).sum() > 50
    for method in ("bvh", "brute_force"):
        r = sl.query(mesh, points, backend="cpu", method=method, sign="auto", precision="double")
        assert np.array_equal(r.distance < 0, inside), method


@pytest.mark.parametrize("name", sorted(PLACEMENTS))
def test_sdf_query_on_the_cad_box_writes_no_warning(name, tmp_path):
    vertices, faces = placed(name)
    obj = tmp_path / "cad_box.obj"
    with open(obj, "w") as f:
        f.writelines(f"v {x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in vertices)
        f.writelines(f"f {a + 1:d} {b + 1:d} {c + 1:d}\n" for a, b, c in faces)
    points, inside = points_clear_of_the_surface(name, n=100)
    np.save(tmp_path / "points.npy", points)
    r = subprocess.run([SDF_QUERY, str(obj), str(tmp_path / "points.npy"), "--backend", "cpu", "--sign", "auto",
                        "--out", str(tmp_path / "out.npy")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    out = np.load(tmp_path / "out.npy")
    assert np.array_equal(out[:, 0] < 0, inside)
