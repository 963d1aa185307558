"""Training data for neural implicit models: points near a mesh's surface and in a box around
it, with the exact signed distance, occupancy and normal of each, reproducible from a seed.

    import sdf_lattices as sl
    s = sl.data.sample_near_surface("bunny.obj", 250_000, seed=1)
    s.points, s.sdf, s.occupancy, s.normals      # (N, 3), (N,), (N,), (N, 3)
    b = sl.data.sample_batch(["bunny.obj", "shape:torus"], 100_000)   # arrays (2, N, ...)

The meshes are first normalised to the unit cube (normalize_to_unit_cube): the bounding box's
centre goes to the origin and its largest side to length 1, so that sigmas and boxes mean the
same for every mesh. The points are drawn as DeepSDF (Park et al., CVPR 2019) draws them: an
area-weighted random triangle, a uniform point on it and a Gaussian offset N(0, sigma^2) per
axis, at several sigmas, plus points uniform in a box. Their values are not estimated from a
point cloud (as mesh_to_sdf does, docs/ml-data.md compares): query() computes the exact
signed distance to the triangles (sign by pseudonormals, or by the winding number where the
mesh is open or self-intersecting: docs/winding.md), and its exact unit gradient is the normal.

The random numbers are SplitMix64 with the transforms of core/sampling/point_sets.cpp, in
NumPy, so a seed gives the same points with any NumPy version; a group of points drawn with
seed s are the C++ point set's (gaussian_surface, uniform_box) with seed s, but for the last
bits of a Gaussian offset (NumPy's log and cos against the C library's).
"""
import os
import tempfile
import types
from typing import NamedTuple

import numpy as np

import sdf_lattices as _sl   # the package (partly initialised while it imports this module): names resolve at call time

# DeepSDF's two variances, 0.0025 and 0.00025 on the unit sphere, are standard deviations 0.05
# and 0.016; on the unit cube (half the length) 0.025 and 0.008. 6% of the points uniform in
# the box, as DeepSDF and mesh_to_sdf.
DEFAULT_SIGMAS = (0.025, 0.008)
DEFAULT_UNIFORM_FRACTION = 0.06

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_CHUNK = 1 << 20   # points per block of random numbers (bounds the generator's memory)


# ---- random numbers (core/sampling/point_sets.cpp's, vectorised) ------------------------------

def _splitmix64(seed, start, count):
    """Outputs start .. start+count-1 of SplitMix64 seeded with seed (output k comes from the
    state seed + (k+1) * golden, so any stretch of the stream is computed directly)."""
    z = np.arange(start + 1, start + count + 1, dtype=np.uint64)
    with np.errstate(over="ignore"):   # uint64 arithmetic wraps, as in C++ (in place: 1 array)
        z *= _GOLDEN
        z += np.uint64(seed)
        z ^= z >> np.uint64(30)
        z *= np.uint64(0xBF58476D1CE4E5B9)
        z ^= z >> np.uint64(27)
        z *= np.uint64(0x94D049BB133111EB)
        z ^= z >> np.uint64(31)
    return z


def _uniform(seed, start, count):
    """Uniform in [0, 1): the top 53 bits of each output."""
    return (_splitmix64(seed, start, count) >> np.uint64(11)).astype(np.float64) * 2.0 ** -53


def _check_seed(seed):
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) < 2 ** 64:
        raise ValueError(f"seed: expected an integer in [0, 2^64), got {seed!r}")
    return int(seed)


def _group_seeds(seed, count):
    """One seed per point group, drawn from the caller's seed."""
    return [int(s) for s in _splitmix64(seed, 0, count)]


def uniform_box(lo, hi, count, seed):
    """count points uniform in the box [lo, hi) ((3,) each), float64 (N, 3): the C++ point set
    uniform_box's draws (x, y, z per point) for the same seed."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or not np.all(np.isfinite(lo)) or not np.all(hi > lo):
        raise ValueError(f"box: expected finite corners lo < hi of 3 values each, got {lo.tolist()} and {hi.tolist()}")
    u = _uniform(_check_seed(seed), 0, 3 * _check_count(count)).reshape(-1, 3)
    return lo + u * (hi - lo)


def surface_gaussian(vertices, triangles, count, sigma, seed):
    """count points on the triangles (area-weighted) plus an N(0, sigma^2) offset per axis:
    points (N, 3) float64 and the triangle each was drawn on (N,) (indices into triangles).
    sigma 0 gives points on the surface. The C++ point set gaussian_surface's draws (triangle,
    two barycentrics, three Box-Muller normals per point) for the same seed."""
    seed, count = _check_seed(seed), _check_count(count)
    if not (np.isfinite(sigma) and sigma >= 0):
        raise ValueError(f"sigma: expected a finite value >= 0, got {sigma!r}")
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    if len(t) == 0:
        raise ValueError("surface points: the mesh has no triangles")
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    cr = np.cross(b - a, c - a)
    cumulative = np.cumsum(0.5 * np.sqrt(cr[:, 0] * cr[:, 0] + cr[:, 1] * cr[:, 1] + cr[:, 2] * cr[:, 2]))
    points = np.empty((count, 3))
    tri = np.empty(count, dtype=np.int64)
    for begin in range(0, count, _CHUNK):
        n = min(_CHUNK, count - begin)
        u = _uniform(seed, 9 * begin, 9 * n).reshape(n, 9)
        i = np.minimum(np.searchsorted(cumulative, u[:, 0] * cumulative[-1], side="right"), len(t) - 1)
        s, r = u[:, 1].copy(), u[:, 2].copy()
        fold = s + r > 1          # fold the square onto the triangle: uniform barycentrics
        s[fold], r[fold] = 1 - s[fold], 1 - r[fold]
        normal = np.sqrt(-2.0 * np.log(1.0 - u[:, 3::2])) * np.cos(6.283185307179586 * u[:, 4::2])
        ai = a[i]
        points[begin:begin + n] = ai + (b[i] - ai) * s[:, None] + (c[i] - ai) * r[:, None] + normal * sigma
        tri[begin:begin + n] = i
    return points, tri


# The most points drawn per mesh: the largest lattice sampled (2^36), checked before any array is made.
_MAX_COUNT = 1 << 36


def _check_count(count):
    if isinstance(count, (bool, np.bool_)) or not isinstance(count, (int, np.integer)) or count < 0:
        raise ValueError(f"count: expected a non-negative integer, got {count!r}")
    if count > _MAX_COUNT:
        raise ValueError(f"count: expected at most 2^36 points per mesh, got {count}")
    return int(count)


def _check_sigmas(sigmas):
    """sigmas as a tuple of floats; a single number or text is named, not iterated."""
    if isinstance(sigmas, (str, bytes)) or not hasattr(sigmas, "__iter__"):
        raise ValueError(f"sigmas: expected a sequence of standard deviations, e.g. (0.025, 0.008), got {sigmas!r}")
    out = []
    for s in sigmas:
        if isinstance(s, (str, bytes, bool, np.bool_)):
            raise ValueError(f"sigmas: expected numbers, got {s!r}")
        try:
            out.append(float(s))
        except (TypeError, ValueError):
            raise ValueError(f"sigmas: expected numbers, got {s!r}") from None
    return tuple(out)


# ---- meshes ---------------------------------------------------------------------------------

class Normalization(NamedTuple):
    """unit = (world - center) / scale; world = unit * scale + center. Distances scale by scale."""
    center: np.ndarray
    scale: float


def normalize_to_unit_cube(mesh, padding=0.0):
    """normalize_to_unit_cube(mesh, padding=0.0) -> (Mesh, Normalization)

    The mesh moved and scaled uniformly so that its bounding box is centred at the origin and
    its largest side is 1 - 2 * padding: it fits in [-0.5 + padding, 0.5 - padding]^3. Returns
    the new Mesh (its triangles are the prepared mesh's, in the same order) and the
    Normalization that maps back: world = unit * scale + center.
    """
    mesh = _sl.as_mesh(mesh)
    if not (0.0 <= padding < 0.5):
        raise ValueError(f"padding: expected a value in [0, 0.5), got {padding!r}")
    lo, hi = (np.array(corner) for corner in mesh.bounds)
    extent = float(np.max(hi - lo))
    if not extent > 0:
        raise ValueError("normalize_to_unit_cube: the mesh's bounding box is a point")
    center = 0.5 * (lo + hi)
    scale = extent / (1.0 - 2.0 * padding)
    unit = _sl.Mesh((mesh.vertices - center) / scale, mesh.faces, name=_mesh_name(mesh))
    return unit, Normalization(center, scale)


def _mesh_name(mesh):
    name = getattr(mesh, "name", None)
    return name if isinstance(name, str) and name else "mesh"


# ---- samples --------------------------------------------------------------------------------

class Samples:
    """Sample points and their exact values. Arrays (leading batch axis B for sample_batch):
    points (N, 3), sdf (N,) signed distance (negative inside), occupancy (N,) bool (sdf < 0),
    normals (N, 3) unit (the distance's exact gradient; on-surface points: their triangle's
    normal), triangle (N,) int32 closest triangle (input face order; on-surface points: the
    triangle drawn), group (N,) int8 index
    into groups, the names of the point groups ("surface", "gaussian(sigma=0.025)", ...,
    "uniform"). center (3,) and scale: the normalisation (world = points * scale + center;
    identity without normalising). mesh: the Mesh the values are of (a list for a batch)."""

    ARRAYS = ("points", "sdf", "occupancy", "normals", "triangle", "group", "center", "scale")

    def __init__(self, **fields):
        self.__dict__.update(fields)

    def arrays(self):
        """The arrays as a dict (for np.savez and ML data loaders), with groups as strings."""
        out = {name: getattr(self, name) for name in self.ARRAYS}
        out["groups"] = np.array(self.groups)
        return out

    def save(self, path, overwrite=False):
        """Writes arrays() to a .npz file, atomically; an existing file is kept unless overwrite."""
        path = os.fspath(path)
        if not path.endswith(".npz"):
            raise ValueError(f"{path}: expected a .npz file name")
        if os.path.exists(path) and not overwrite:
            raise ValueError(f"{path} exists (overwrite=True replaces it)")
        fd, tmp = tempfile.mkstemp(suffix=".npz", dir=os.path.dirname(os.path.abspath(path)))
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez(f, **self.arrays())
            os.replace(tmp, path)
        except BaseException:
            os.unlink(tmp)
            raise

    def __len__(self):
        return self.points.shape[-2]

    def __repr__(self):
        return f"<sdf_lattices.data.Samples {self.points.shape[:-1]} points, groups {list(self.groups)}>"


def _group_counts(count, sigmas, uniform_fraction, surface_fraction):
    """Points per group: surface, one per sigma, uniform (the near-surface rest split evenly,
    the remainder to the first sigmas)."""
    for name, f in (("uniform_fraction", uniform_fraction), ("surface_fraction", surface_fraction)):
        if not 0.0 <= f <= 1.0:
            raise ValueError(f"{name}: expected a value in [0, 1], got {f!r}")
    if uniform_fraction + surface_fraction > 1.0:
        raise ValueError(f"uniform_fraction + surface_fraction: expected at most 1, got {uniform_fraction + surface_fraction}")
    uniform = int(round(count * uniform_fraction))
    surface = int(round(count * surface_fraction))
    near = count - uniform - surface
    if near and not sigmas:
        raise ValueError("sigmas: expected at least one sigma for the near-surface points")
    share = [near // len(sigmas) + (k < near % len(sigmas)) for k in range(len(sigmas))] if sigmas else []
    return surface, share, uniform


def sample_near_surface(mesh, count=250_000, *, sigmas=DEFAULT_SIGMAS, uniform_fraction=DEFAULT_UNIFORM_FRACTION,
                        surface_fraction=0.0, box=None, margin=0.1, seed=0, normalize=True, padding=0.0,
                        dtype="float64", sign="auto", backend="auto", method="bvh", precision="double", threads=0):
    """sample_near_surface(mesh, count=250000, *, sigmas=(0.025, 0.008), uniform_fraction=0.06, surface_fraction=0.0, box=None, margin=0.1, seed=0, normalize=True, padding=0.0, dtype="float64", sign="auto", backend="auto", method="bvh", precision="double", threads=0) -> Samples

    count points with exact signed distance, occupancy and normals: surface_fraction of them
    on the surface, uniform_fraction uniform in the box, the rest near the surface, split
    evenly over sigmas (a Gaussian offset of standard deviation sigma per axis). mesh: what
    sdf_lattices.as_mesh takes (a Mesh, a file name, "shape:NAME", (vertices, faces), a
    trimesh or Open3D mesh). normalize: first move the mesh into the unit cube
    (normalize_to_unit_cube, with padding); sigmas, box and the points are then in its units. box: ((x0, y0, z0), (x1, y1, z1)); by default the cube around the mesh's
    bounding box whose side is the largest extent plus margin of it on each side
    ([-0.6, 0.6]^3 for a normalised mesh). seed: the same seed gives the same points.
    dtype "float32" rounds the points to float32 before they are queried, so that the values
    are exact for the points as stored. sign, backend, method, precision, threads: as query();
    precision "double" (the default here) searches in double: a float search may pick a
    triangle up to ~1e-4 (relative) farther than the nearest near an edge where two are
    almost as near (its distance is still evaluated in double).
    """
    drawn = _draw(mesh, count, sigmas=sigmas, uniform_fraction=uniform_fraction, surface_fraction=surface_fraction,
                  box=box, margin=margin, seed=seed, normalize=normalize, padding=padding, dtype=dtype)
    result = _sl.query(drawn.mesh, drawn.points.astype(np.float64), backend=backend, method=method, sign=sign,
                       precision=precision, threads=threads)
    return _labelled(drawn, result)


# sample_near_surface's sampler keywords and their defaults (precision "double": see its doc).
_SAMPLER_DEFAULTS = {"sign": "auto", "backend": "auto", "method": "bvh", "precision": "double", "threads": 0}


def _draw(mesh, count, *, sigmas=DEFAULT_SIGMAS, uniform_fraction=DEFAULT_UNIFORM_FRACTION, surface_fraction=0.0,
          box=None, margin=0.1, seed=0, normalize=True, padding=0.0, dtype="float64"):
    """The points of sample_near_surface, before they are queried (the mesh normalised)."""
    mesh = _sl.as_mesh(mesh)
    count, seed = _check_count(count), _check_seed(seed)
    if dtype not in ("float32", "float64", np.float32, np.float64):
        raise ValueError(f"dtype: expected \"float32\" or \"float64\", got {dtype!r}")
    dtype = np.dtype(dtype)
    sigmas = _check_sigmas(sigmas)
    for s in sigmas:
        if not (np.isfinite(s) and s > 0):
            raise ValueError(f"sigmas: expected finite values > 0, got {s!r}")
    if normalize:
        mesh, norm = normalize_to_unit_cube(mesh, padding)
    else:
        norm = Normalization(np.zeros(3), 1.0)
    if box is None:
        lo, hi = (np.array(corner) for corner in mesh.bounds)
        half = 0.5 * float(np.max(hi - lo)) * (1.0 + 2.0 * margin)
        box = (0.5 * (lo + hi) - half, 0.5 * (lo + hi) + half)

    n_surface, n_near, n_uniform = _group_counts(count, sigmas, uniform_fraction, surface_fraction)
    seeds = _group_seeds(seed, 2 + len(sigmas))
    vertices, triangles = mesh.vertices, mesh.faces
    groups, parts, on_surface = [], [], None
    if n_surface:
        on_surface, on_surface_tri = surface_gaussian(vertices, triangles, n_surface, 0.0, seeds[0])
        groups.append("surface")
        parts.append(on_surface)
    for k, (sigma, n) in enumerate(zip(sigmas, n_near)):
        if n:
            groups.append(f"gaussian(sigma={sigma:g})")
            parts.append(surface_gaussian(vertices, triangles, n, sigma, seeds[1 + k])[0])
    if n_uniform:
        groups.append("uniform")
        parts.append(uniform_box(box[0], box[1], n_uniform, seeds[-1]))
    group = np.concatenate([np.full(len(p), g, dtype=np.int8) for g, p in enumerate(parts)]) if parts else np.zeros(0, np.int8)
    points = np.concatenate(parts).astype(dtype) if parts else np.zeros((0, 3), dtype)
    return types.SimpleNamespace(mesh=mesh, vertices=vertices, triangles=triangles, points=points, dtype=dtype,
                                 group=group, groups=tuple(groups), norm=norm, on_surface=on_surface,
                                 on_surface_tri=on_surface_tri if n_surface else None)


def _labelled(drawn, result):
    """The Samples of drawn points and their query result."""
    mesh, dtype, on_surface = drawn.mesh, drawn.dtype, drawn.on_surface
    sdf, normals, triangle = result.distance, np.array(result.gradient), np.array(result.triangle)
    if on_surface is not None:   # on their triangle (up to rounding): its normal, not the gradient's
        vertices = drawn.vertices
        t = drawn.triangles[drawn.on_surface_tri]
        n = np.cross(vertices[t[:, 1]] - vertices[t[:, 0]], vertices[t[:, 2]] - vertices[t[:, 0]])
        normals[:len(on_surface)] = n / np.linalg.norm(n, axis=1, keepdims=True)
        triangle[:len(on_surface)] = mesh.source_triangle[drawn.on_surface_tri]
    return Samples(points=drawn.points, sdf=sdf.astype(dtype), occupancy=sdf < 0, normals=normals.astype(dtype),
                   triangle=triangle, group=drawn.group, groups=drawn.groups,
                   center=np.asarray(drawn.norm.center, dtype=np.float64), scale=np.float64(drawn.norm.scale), mesh=mesh)


def sample_batch(meshes, count=250_000, *, seed=0, **options):
    """sample_batch(meshes, count=250000, *, seed=0, **options) -> Samples

    sample_near_surface for each mesh of a list, with the same options, stacked: arrays of
    shape (B, count, ...) (center (B, 3), scale (B,)), mesh a list. Mesh i is sampled with
    seed + i, so its points are those of sample_near_surface(meshes[i], count, seed=seed + i).
    Every mesh's points are queried in one native call (sdf_lattices.query_batch), with the
    values of sample_near_surface's one query per mesh, bit for bit.
    """
    meshes = list(meshes)
    if not meshes:
        raise ValueError("meshes: expected at least one mesh")
    seed = _check_seed(seed)
    if seed + len(meshes) > 2 ** 64:
        raise ValueError(f"seed: seed + len(meshes) must stay below 2^64, got {seed}")
    sampler = dict(_SAMPLER_DEFAULTS)
    sampler.update({k: options.pop(k) for k in _SAMPLER_DEFAULTS if k in options})
    count = _check_count(count)
    drawn = [_draw(m, count, seed=seed + i, **options) for i, m in enumerate(meshes)]
    results = _sl.query_batch([_sl.SDF(d.mesh, **sampler) for d in drawn], [d.points.astype(np.float64) for d in drawn])
    each = [_labelled(d, r) for d, r in zip(drawn, results)]
    stacked = {name: np.stack([getattr(s, name) for s in each]) for name in Samples.ARRAYS}
    return Samples(**stacked, groups=each[0].groups, mesh=[s.mesh for s in each])
