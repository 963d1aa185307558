"""Exact signed distance fields of triangle meshes on CC and BCC lattices.

Meshes (load_mesh, Mesh), a mesh bound to its sampler and queried many times (SDF), exact
queries of arbitrary points (query, and the one-liner sdf), sampled fields (sample,
read_field, Field), their reconstruction (Field.reconstruct) and ray-cast images (render),
all with NumPy arrays, or with GPU tensors (PyTorch, CuPy, JAX) that stay on the GPU. The same code as the command-line tools: query() equals sdf-query,
sample() equals a run-experiment field, bit for bit. Signed distance is negative inside;
gradients are unit vectors; triangles are 0-based in the input's face order.

A `mesh` argument takes an sdf_lattices.Mesh, a mesh file path, (vertices, faces) arrays,
an Open3D TriangleMesh (legacy or tensor) or any object with vertices and faces arrays
(trimesh). Errors raise ValueError (a bad argument), TypeError (an argument of the wrong
kind), FileNotFoundError (read_field of a missing file) or RuntimeError (a bad file, a
missing backend) with the tools' messages; warnings go through Python's `warnings`
(SdfWarning, MeshWarning); long calls take progress=True or a callable and stop on Ctrl-C.

The package is the compiled extension sdf_lattices._core (every name re-exported here) and
pure-Python parts beside it.
"""
from . import _core
from ._core import *  # noqa: F401,F403  (every public name of the extension)
from ._core import __version__, build_commit  # noqa: F401
from ._adapters import as_mesh  # noqa: F401
from ._fields import read_field  # noqa: F401
from ._warnings import MeshWarning, SdfWarning  # noqa: F401
from . import _gpu
from ._gpu import DeviceQueryResult  # noqa: F401

# GPU tensors (PyTorch, CuPy, JAX) in and out without copies: SDF.query, query, sdf and
# query_batch take them (sdf_lattices._gpu); torch autograd on the CPU and CUDA (_torch.py).
query, sdf, query_batch = _gpu.install(_core)
# Wrong keywords and types named in words, not as pybind11's signature dumps (_arguments.py).
from . import _arguments  # noqa: E402
render = _arguments.install(_core)
# band=W: a sparse narrow band, sdf_lattices.SparseField (_sparse.py); installed after _arguments.
from . import _sparse  # noqa: E402
sample = _sparse.install(_core)

from . import data  # noqa: E402,F401  (ML training data: sdf_lattices.data.sample_near_surface, ...)
from ._build_info import build_info  # noqa: E402,F401  (what the build found: CUDA, MPI, OpenVDB, OpenImageIO)
