"""Meshes as users hold them: every function that takes a `mesh` argument accepts

- an sdf_lattices.Mesh (used as it is),
- a mesh file path (str or os.PathLike; load_mesh),
- a (vertices, faces) pair of arrays of any float and integer dtype,
- an Open3D TriangleMesh, legacy (open3d.geometry: vertices, triangles) or tensor
  (open3d.t.geometry: vertex.positions, triangle.indices),
- any object with `vertices` and `faces` arrays (trimesh.Trimesh and the like).

Each becomes a Mesh (prepared once: build an sdf_lattices.SDF to query one mesh many times).
"""
import os

import numpy as np

_ACCEPTED = ("an sdf_lattices.Mesh, a mesh file path, (vertices, faces) arrays, an Open3D TriangleMesh "
             "(legacy or tensor), or an object with vertices and faces arrays (e.g. trimesh.Trimesh)")


def _tensor_array(tensor):
    """An Open3D core.Tensor (on any device) as a NumPy array."""
    if hasattr(tensor, "cpu"):
        tensor = tensor.cpu()
    return tensor.numpy()


def _open3d_tensor_arrays(obj):
    vertex, triangle = obj.vertex, obj.triangle
    positions = vertex["positions"] if "positions" in vertex else None
    indices = triangle["indices"] if "indices" in triangle else None
    if positions is None or indices is None:
        raise ValueError("mesh: this Open3D tensor TriangleMesh has no vertex 'positions' or triangle 'indices'")
    return _tensor_array(positions), _tensor_array(indices)


def _array(x):
    """x as a NumPy array; a torch tensor on any device, also one that requires grad, through
    detach().cpu() (its gradients are sdf_lattices._torch's business)."""
    if type(x).__module__.split(".")[0] == "torch" and hasattr(x, "detach"):
        x = x.detach().cpu()
    return np.asarray(x)


def mesh_arrays(obj):
    """(vertices, faces) of a mesh-like object, or None when it is not one."""
    if isinstance(obj, (tuple, list)) and len(obj) == 2:
        return _array(obj[0]), _array(obj[1])
    if hasattr(obj, "vertex") and hasattr(obj, "triangle"):  # open3d.t.geometry.TriangleMesh
        return _open3d_tensor_arrays(obj)
    if hasattr(obj, "vertices") and hasattr(obj, "triangles"):  # open3d.geometry.TriangleMesh
        return np.asarray(obj.vertices), np.asarray(obj.triangles)
    if hasattr(obj, "vertices") and hasattr(obj, "faces"):  # trimesh.Trimesh and the like
        return _array(obj.vertices), _array(obj.faces)
    return None


def as_mesh(obj):
    """The sdf_lattices.Mesh that `obj` stands for; TypeError naming what is accepted."""
    from . import _core

    if isinstance(obj, _core.Mesh):
        return obj
    if isinstance(obj, (str, os.PathLike)):
        return _core.load_mesh(os.fspath(obj))
    arrays = mesh_arrays(obj)
    if arrays is None:
        raise TypeError(f"mesh: expected {_ACCEPTED}; got {type(obj).__module__}.{type(obj).__qualname__}")
    vertices, faces = arrays
    return _core.Mesh(vertices, faces, name=type(obj).__name__ if not isinstance(obj, (tuple, list)) else "mesh")
