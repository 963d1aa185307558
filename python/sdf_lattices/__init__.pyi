# Type stubs of the package sdf_lattices (the extension sdf_lattices._core and its pure-Python
# parts), so that editors complete the API. tests/python_module/test_python_api.py checks that
# every public name and member is here.
import os
import types
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, TypedDict, Union, Unpack, overload

import numpy as np
import numpy.typing as npt

__version__: str
build_commit: str

Vec3 = Tuple[float, float, float]
ArrayF = npt.NDArray[np.float64]
ArrayR = Union[npt.NDArray[np.float64], npt.NDArray[np.float32]]  # float32 with dtype="float32"
DType = Union[str, type, np.dtype]  # "float64" (the default) or "float32"
ArrayI = npt.NDArray[np.int32]
Progress = Union[None, bool, Callable[[int, int], Any]]
MeshLike = Union["Mesh", str, os.PathLike, Tuple[npt.ArrayLike, npt.ArrayLike], Any]
"""An sdf_lattices.Mesh, a mesh file path, (vertices, faces), an Open3D TriangleMesh or any
object with vertices and faces arrays (trimesh)."""
Grids = Union[ArrayF, Tuple[ArrayF, ArrayF]]

class SamplerKeywords(TypedDict, total=False):
    """The sampler keywords of SDF, query, sdf and sample: the keys of a config's "sampler"
    object (core/sampling/sampler_options.h), with its defaults; sign also takes "none"."""
    backend: str                  # "auto", "cpu", "cuda"
    method: str                   # "bvh", "brute_force"
    kernel: str                   # "" = the backend's default
    precision: str                # "float", "double"
    sign: str                     # "auto", "pseudonormal", "winding", "none"
    threads: int                  # 0 = all cores
    bcc_strategy: str             # "two_grids", "double_resolution"
    device: int                   # CUDA device ordinal
    devices: Union[str, Sequence[int]]  # "all" or [0, 1]: several GPUs of this process; [] = device
    max_points_per_piece: int     # 0 = automatic
    max_triangles_per_chunk: int  # 0 = automatic
    points_per_thread: int        # 0, 1, 2, 4, 8
    band_width: float             # 0 = no band (lattices only)
    min_points_per_device: int    # with devices: fewest points a GPU gets before a job is split (default 2**23)

class SdfWarning(UserWarning): ...
class MeshWarning(SdfWarning): ...

class Mesh:
    def __init__(self, vertices: npt.ArrayLike, faces: npt.ArrayLike, name: str = "mesh", weld_tolerance: float = 0.0,
                 check_intersections: bool = True) -> None: ...
    name: str
    source: str
    sha256: str
    vertices: ArrayF
    faces: ArrayI
    source_triangle: ArrayI
    input_vertices: ArrayF
    input_faces: ArrayI
    bounds: Tuple[Vec3, Vec3]
    closed: bool
    consistently_oriented: bool
    orientation: str
    components: int
    sign_reliable: bool
    warnings: List[str]
    report: Dict[str, Any]

class QueryResult:
    distance: ArrayR
    gradient: ArrayR
    triangle: ArrayI
    closest_point: ArrayR
    barycentric: ArrayR
    winding: Optional[ArrayF]
    winding_error_bound: Optional[ArrayF]
    sign: str
    sampler: str
    timings_seconds: Dict[str, float]
    search_certificate: Dict[str, int]  # points, reranked, full_double
    devices: Dict[str, Any]       # count, used, split, min_points_per_device, why_not | why_fewer
    def __len__(self) -> int: ...

class DeviceQueryResult:
    """Results of GPU points (and of torch points with differentiable=True, CPU too): arrays of
    the input's library (torch, cupy, jax) on its device; the distance differentiable."""
    distance: Any
    gradient: Any
    triangle: Any
    sign: str
    sampler: str
    def __len__(self) -> int: ...

class Field:
    def __init__(self, values: Union[npt.ArrayLike, Tuple[npt.ArrayLike, npt.ArrayLike]], origin: Sequence[float],
                 spacing: float, lattice: str = "cc", gradient: Any = None, triangle: Any = None) -> None: ...
    lattice: str
    origin: Vec3
    spacing: float
    resolution: Tuple[int, int, int]
    notation: str
    num_points: int
    grid_origins: Union[Vec3, Tuple[Vec3, Vec3]]
    lattice_info: Dict[str, Any]
    values: Grids
    gradient: Optional[Grids]
    triangle: Optional[Union[ArrayI, Tuple[ArrayI, ArrayI]]]
    precision: str
    sampler: Dict[str, Any]
    mesh: Dict[str, Any]
    seconds: float
    def points(self) -> Grids: ...
    def write(self, path: str, dtype: str = "float32", overwrite: bool = False, closest_triangle: bool = True) -> None: ...
    def reconstruct(self, points: npt.ArrayLike, interpolator: str = "", derivatives: str = "", sigma2: float = 0.5,
                    sigma_units: str = "lattice", threads: int = 0, outside: str = "nan") -> Tuple[ArrayF, ArrayF]: ...

class SparseField:
    distance: ArrayF
    gradient: Optional[ArrayF]
    triangle: Optional[ArrayI]
    points: ArrayF
    indices: npt.NDArray[np.int64]
    subgrid: npt.NDArray[np.int8]
    width: float
    lattice: str
    resolution: Tuple[int, int, int]
    origin: Vec3
    spacing: float
    num_points: int
    active_blocks: int
    counts: Dict[str, int]
    nbytes: int
    precision: str
    mesh: Dict[str, Any]
    def to_dense(self) -> Field: ...
    def write(self, path: str, overwrite: bool = False, closest_triangle: bool = False,
              dtype: str = "float32") -> List[str]: ...
    def reconstruct(self, points: Any, interpolator: str = "", derivatives: str = "", sigma2: float = 0.5,
                    sigma_units: str = "lattice", threads: int = 0,
                    outside: str = "nan") -> Tuple[np.ndarray, np.ndarray]: ...
    def to_openvdb(self) -> Dict[str, Any]: ...
    def __len__(self) -> int: ...

class SDF:
    def __init__(self, mesh: MeshLike, **sampler: Unpack[SamplerKeywords]) -> None: ...
    mesh: Mesh
    sampler: str
    sign: str
    sign_reason: str
    precision: str
    build_seconds: float
    backend: str
    device: int
    def query(self, points: Any, winding: Union[bool, str] = False, progress: Progress = None,
              differentiable: bool = False, dtype: DType = "float64") -> Union[QueryResult, DeviceQueryResult]: ...
    def refit(self, new_vertices: Any) -> "SDF": ...
    @overload
    def sample(self, lattice: str = "cc", resolution: Union[None, int, Sequence[int]] = None, samples: Optional[int] = None,
               margin: Optional[float] = None, bounds: Optional[Tuple[Sequence[float], Sequence[float]]] = None,
               spacing: Optional[float] = None, origin: Optional[Sequence[float]] = None,
               progress: Progress = None) -> Field: ...
    @overload
    def sample(self, lattice: str = "cc", resolution: Union[None, int, Sequence[int]] = None, samples: Optional[int] = None,
               margin: Optional[float] = None, bounds: Optional[Tuple[Sequence[float], Sequence[float]]] = None,
               spacing: Optional[float] = None, origin: Optional[Sequence[float]] = None,
               progress: Progress = None, *, band: float, gradient: bool = True, closest_triangle: bool = True) -> SparseField: ...

def as_mesh(mesh: MeshLike) -> Mesh: ...
def cuda_available() -> bool: ...
def load_mesh(path: str, weld_tolerance: float = 0.0, check_intersections: bool = True) -> Mesh: ...
def query(mesh: MeshLike, points: Any, progress: Progress = None, winding: Union[bool, str] = False,
          differentiable: bool = False, dtype: DType = "float64",
          **sampler: Unpack[SamplerKeywords]) -> Union[QueryResult, DeviceQueryResult]: ...
def sdf(mesh: MeshLike, points: Any, progress: Progress = None, differentiable: bool = False, dtype: DType = "float64",
        **sampler: Unpack[SamplerKeywords]) -> Any: ...
def query_batch(sdfs: Sequence[SDF], points: Sequence[Any], progress: Progress = None, dtype: DType = "float64",
                differentiable: bool = False) -> List[Union[QueryResult, DeviceQueryResult]]: ...
@overload
def sample(mesh: MeshLike, lattice: str = "cc", resolution: Union[None, int, Sequence[int]] = None,
           samples: Optional[int] = None, margin: Optional[float] = None,
           bounds: Optional[Tuple[Sequence[float], Sequence[float]]] = None, spacing: Optional[float] = None,
           origin: Optional[Sequence[float]] = None, progress: Progress = None, distributed: bool = True,
           **sampler: Unpack[SamplerKeywords]) -> Field: ...
@overload
def sample(mesh: MeshLike, lattice: str = "cc", resolution: Union[None, int, Sequence[int]] = None,
           samples: Optional[int] = None, margin: Optional[float] = None,
           bounds: Optional[Tuple[Sequence[float], Sequence[float]]] = None, spacing: Optional[float] = None,
           origin: Optional[Sequence[float]] = None, progress: Progress = None, distributed: bool = True, *,
           band: float, gradient: bool = True, closest_triangle: bool = True, **sampler: Unpack[SamplerKeywords]) -> SparseField: ...
def read_field(path: Union[str, os.PathLike]) -> Union[Field, SparseField, Dict[str, Any]]: ...
def lattice_kinds() -> List[Dict[str, Any]]: ...
def read_field_file(path: str) -> Field: ...
def render(field: Field, view: str = "three_quarter", size: Union[int, Tuple[int, int]] = 512, interpolator: str = "",
           derivatives: str = "", backend: str = "auto", precision: str = "float", eye: Optional[Sequence[float]] = None,
           target: Optional[Sequence[float]] = None, up: Sequence[float] = (0, 1, 0), fov: float = 30.0,
           mesh: Optional[MeshLike] = None, threads: int = 0, progress: Progress = None) -> npt.NDArray[np.float32]: ...
def distributed() -> Dict[str, Any]: ...

# sdf_lattices.data (data.py, typed inline): ML training samples with exact values.
data: types.ModuleType
def build_info() -> Dict[str, Any]: ...
