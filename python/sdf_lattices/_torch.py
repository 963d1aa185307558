"""PyTorch autograd of the exact distance, with respect to the points and the mesh's vertices,
for torch tensors on the CPU and on CUDA devices (SDF.query, query, sdf and query_batch with
differentiable=True).

The distance is d(p) = s * |p - c| with c the closest point of the mesh and s the sign, so
  d d / d p   = g, the exact unit gradient the query returns, and
  d d / d V_k = -b_k * g for the three corners V_k of the closest face (b its barycentric
                weights of c, c = sum_k b_k V_k), zero for every other vertex.
The second is the envelope theorem: c minimises |p - x(b)| over the fixed simplex of
weights b, so moving the corners moves d only through x(b*) = sum_k b_k V_k at the optimal
weights, and on an edge or a vertex of the closest face (some b_k = 0, or one b_k = 1) the
same formula holds (the weights stay those of the closest point; a corner with b_k = 0 gets
nothing). Exceptions, where d is not differentiable and one of its one-sided gradients is
given: points on the medial axis (several closest points: the query's closest triangle
decides), and points on the surface (d = 0: the gradient is the sign's outward normal
there). The sign s is constant under small moves away from the surface; first order only
(the gradient is not itself differentiated).

The vertices are those of the caller's (vertices, faces) pair when the vertices are a torch
tensor (SDF((V, F)), query((V, F), ...), sdf((V, F), ...), SDF.refit(V)): gradients land on
the caller's rows, through the query's triangle (the caller's face numbering) and the
caller's faces (Mesh.input_faces). On the CPU the barycentric weights are the query's own
(QueryResult.barycentric); on a GPU they are computed on the device from the closest point
c = p - d * g and the face's corners (barycentric_of, which the CPU tests check against the
query's).
"""
import weakref

import numpy as np

# SDF -> the torch tensor its mesh's vertices came from (held weakly by the SDF).
_vertex_tensors = weakref.WeakKeyDictionary()


def is_tensor(x):
    return type(x).__module__.split(".")[0] == "torch" and hasattr(x, "requires_grad")


def as_numpy(x):
    """A torch tensor (any device, with or without requires_grad) as a NumPy array; others as they are."""
    if is_tensor(x):
        return x.detach().cpu().numpy()
    return x


def vertex_tensor_of(mesh):
    """The torch tensor of a mesh argument's vertices ((V, F) or an object with .vertices), or None."""
    vertices = None
    if isinstance(mesh, (tuple, list)) and len(mesh) == 2:
        vertices = mesh[0]
    elif hasattr(mesh, "vertices") and hasattr(mesh, "faces"):
        vertices = getattr(mesh, "vertices", None)
    return vertices if is_tensor(vertices) else None


def remember_vertices(sdf, vertices):
    if vertices is not None:
        _vertex_tensors[sdf] = vertices


def wants_vertices(sdf):
    """Whether the SDF's vertices are a torch tensor that requires grad."""
    vertices = _vertex_tensors.get(sdf)
    return vertices is not None and vertices.requires_grad


def barycentric_of(closest, a, b, c):
    """Weights (N, 3) of the closest points `closest` in the triangles (a, b, c), rows of three:
    the projection's weights, clamped to [0, 1] and summing to 1."""
    import torch

    v0, v1, v2 = b - a, c - a, closest - a
    d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
    d20, d21 = (v2 * v0).sum(1), (v2 * v1).sum(1)
    den = d00 * d11 - d01 * d01
    w1 = (d11 * d20 - d01 * d21) / den
    w2 = (d00 * d21 - d01 * d20) / den
    weights = torch.stack([1.0 - w1 - w2, w1, w2], dim=1).clamp(0.0, 1.0)
    return weights / weights.sum(1, keepdim=True)


def _make_function():
    import torch

    class ExactDistance(torch.autograd.Function):
        """distance(points, vertices) with the exact gradients of the module's doc."""

        @staticmethod
        def forward(ctx, points, vertices, distance, gradient, corners, weights):
            ctx.save_for_backward(gradient, corners, weights)
            ctx.points_dtype = points.dtype
            ctx.vertices_meta = None if vertices is None else (vertices.shape, vertices.dtype, vertices.device)
            return distance

        @staticmethod
        def backward(ctx, grad_distance):
            gradient, corners, weights = ctx.saved_tensors
            g = grad_distance.to(torch.float64)[:, None] * gradient
            grad_points = g.to(ctx.points_dtype) if ctx.needs_input_grad[0] else None
            grad_vertices = None
            if ctx.needs_input_grad[1]:
                shape, dtype, device = ctx.vertices_meta
                contributions = -(weights[:, :, None] * g[:, None, :])  # (N, corner, xyz)
                grad_vertices = torch.zeros((shape[0], 3), dtype=torch.float64, device=g.device)
                grad_vertices.index_add_(0, corners.reshape(-1), contributions.reshape(-1, 3))
                grad_vertices = grad_vertices.to(device=device, dtype=dtype)
            return grad_points, grad_vertices, None, None, None, None

    return ExactDistance


_function = []


def _exact_distance():
    if not _function:
        _function.append(_make_function())
    return _function[0]


def differentiable_distance(sdf, points, distance, gradient, triangle, barycentric=None, dtype="float64"):
    """The distance as a tensor that autograd differentiates with respect to `points` and, when
    the SDF's mesh came from a torch vertex tensor that requires grad, its vertices.
    distance, gradient, triangle: the query's float64 (and int32) tensors on the points'
    device; barycentric: the query's weights (CPU), or None to compute them here."""
    import torch

    out_dtype = torch.float32 if dtype == "float32" else torch.float64
    vertices = _vertex_tensors.get(sdf)
    with_vertices = wants_vertices(sdf)
    if not (points.requires_grad or with_vertices):
        return distance.to(out_dtype, copy=True)
    corners = weights = None
    if with_vertices:
        faces = torch.as_tensor(np.asarray(sdf.mesh.input_faces, dtype=np.int64), device=distance.device)
        if vertices.shape[0] != len(sdf.mesh.input_vertices):
            raise ValueError("vertices: the tensor has %d rows and the SDF's mesh %d input vertices; refit or rebuild "
                             "the SDF with this tensor" % (vertices.shape[0], len(sdf.mesh.input_vertices)))
        corners = faces[triangle.to(torch.int64)]
        if barycentric is None:
            v = vertices.detach().to(device=distance.device, dtype=torch.float64)
            p = points.detach().to(torch.float64)
            closest = p - distance[:, None] * gradient
            barycentric = barycentric_of(closest, v[corners[:, 0]], v[corners[:, 1]], v[corners[:, 2]])
        weights = barycentric.to(device=distance.device, dtype=torch.float64)
    else:
        vertices = None
    # A copy: the forward's output must be a tensor of its own.
    return _exact_distance().apply(points, vertices, distance.to(out_dtype, copy=True), gradient, corners, weights)


__all__ = ["is_tensor", "as_numpy", "vertex_tensor_of", "remember_vertices", "wants_vertices", "barycentric_of", "differentiable_distance"]
