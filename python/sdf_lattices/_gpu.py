"""GPU tensors in and out, without copies.

SDF.query, query and sdf take points that live on a CUDA device: any object with
`__cuda_array_interface__` (PyTorch CUDA tensors, CuPy arrays, Numba) or with DLPack
(`__dlpack__`, e.g. JAX arrays on a GPU). The points are read where they are (float32 or
float64, any strides), the search runs on that device, and the results are written into
new arrays of the input's own library on the same device, in input order: nothing goes
through the host. The numbers equal the host path's bit for bit (the same sampler, the same
search; float32 points are the float32 values the host path would read).

The call is ordered after the work already queued on the input's stream (the stream the
array interface names, else the library's current stream) and returns when the results are
written, so that any later work on that stream sees them.

With torch, `differentiable=True` returns a distance that autograd differentiates with the
exact gradient (d distance / d point = gradient).
"""

_FLOAT_TYPES = {"<f4": True, "<f8": False}


def is_device_array(points):
    """Whether `points` lives on a CUDA device (array interface, or DLPack device type CUDA)."""
    if _cuda_interface(points) is not None:
        return True
    dlpack_device = getattr(points, "__dlpack_device__", None)
    if dlpack_device is None:
        return False
    try:
        return dlpack_device()[0] in (2, 13)  # kDLCUDA, kDLCUDAManaged
    except Exception:
        return False


def _cuda_interface(x):
    try:
        return x.__cuda_array_interface__
    except (AttributeError, RuntimeError):  # torch: CPU tensors, and tensors that require grad
        return None


def _library(x):
    return type(x).__module__.split(".")[0]


class _View:
    """The input as a CUDA array of a library that can also make the outputs (torch or cupy)."""

    def __init__(self, points):
        self.original = points
        self.back = None  # converts an output back to the input's library (JAX)
        x = points
        if _library(x) == "torch" and x.requires_grad:
            x = x.detach()
        if (_cuda_interface(x) is None or _library(x) not in ("torch", "cupy")) and hasattr(points, "__dlpack__"):
            # DLPack (JAX, whose GPU arrays may also have the array interface, or any object
            # with __dlpack__): a zero-copy view through torch or cupy, which make the results
            x, self.back = _dlpack_view(points)
        self.array = x
        self.library = _library(x)
        if self.library not in ("torch", "cupy"):
            raise TypeError("GPU points: results are made with PyTorch or CuPy, and the input is a %s array; "
                            "install torch or cupy, or pass a NumPy array" % self.library)
        cai = _cuda_interface(x)
        shape, typestr = tuple(cai["shape"]), cai["typestr"]
        if len(shape) != 2 or shape[1] != 3:
            raise ValueError("points: expected an (N, 3) array, got shape %s" % (shape,))
        if typestr not in _FLOAT_TYPES:
            raise TypeError("points: expected float32 or float64 on the GPU, got %s" % typestr)
        self.count = shape[0]
        self.float32 = _FLOAT_TYPES[typestr]
        item = 4 if self.float32 else 8
        strides = cai.get("strides") or (3 * item, item)
        if strides[0] % item or strides[1] % item:
            raise ValueError("points: strides %s are not whole elements" % (strides,))
        self.row, self.column = strides[0] // item, strides[1] // item
        self.pointer = cai["data"][0]
        self.stream = _stream_of(x, cai)
        self.device = x.device.index if self.library == "torch" else x.device.id

    def empty(self, shape, dtype):
        if self.library == "torch":
            import torch
            return torch.empty(shape, dtype=getattr(torch, dtype), device=self.array.device)
        import cupy
        with cupy.cuda.Device(self.device):
            return cupy.empty(shape, dtype=dtype)

    def pointer_of(self, array):
        return array.data_ptr() if self.library == "torch" else array.data.ptr

    def result(self, array):
        return self.back(array) if self.back else array


def _dlpack_view(points):
    for name in ("cupy", "torch"):
        try:
            library = __import__(name)
        except ImportError:
            continue
        view = library.from_dlpack(points)
        return view, (_to_jax if _library(points) in ("jax", "jaxlib") else None)
    raise TypeError("GPU points given through DLPack need CuPy or PyTorch to be installed")


def _to_jax(array):
    """A torch or cupy result as a JAX array on the same device, without a copy."""
    import jax.dlpack
    try:
        return jax.dlpack.from_dlpack(array)
    except TypeError:  # JAX before the __dlpack__ protocol takes the capsule
        return jax.dlpack.from_dlpack(array.__dlpack__())


def _stream_of(x, cai):
    stream = cai.get("stream")
    if stream is not None:
        return int(stream)
    if _library(x) == "torch":
        import torch
        return int(torch.cuda.current_stream(x.device).cuda_stream)
    import cupy
    return int(cupy.cuda.get_current_stream().ptr)


class DeviceQueryResult:
    """Results of a query of GPU points, arrays of the input's library on its device, in input
    order: distance (N,) float64, gradient (N, 3) float64, triangle (N,) int32 (the caller's
    face order); sign and sampler as in QueryResult. Closest points, barycentric coordinates
    and winding numbers are host-path outputs (pass a NumPy array for them)."""

    def __init__(self, distance, gradient, triangle, sign, sampler):
        self.distance, self.gradient, self.triangle = distance, gradient, triangle
        self.sign, self.sampler = sign, sampler

    def __len__(self):
        return int(self.distance.shape[0])

    def __repr__(self):
        return "<sdf_lattices.DeviceQueryResult: %d points on %s, sign '%s', sampler '%s'>" % (
            len(self), getattr(self.distance, "device", "the GPU"), self.sign, self.sampler)


def query_device(sdf, points, differentiable=False):
    """The device path of SDF.query for GPU points (see the module's doc)."""
    if sdf.backend != "cuda":
        raise ValueError("points on a GPU need an SDF built with backend='cuda' (or 'auto' on a machine with a GPU); "
                         "this one's sampler is '%s'" % sdf.sampler)
    view = _View(points)
    n = view.count
    distance, gradient, triangle = view.empty((n,), "float64"), view.empty((n, 3), "float64"), view.empty((n,), "int32")
    if n > 0:
        sdf._query_device(view.pointer, n, view.float32, view.row, view.column, view.device, view.stream,
                          view.pointer_of(distance), view.pointer_of(gradient), view.pointer_of(triangle))
    if sdf.sign == "none":  # unsigned: as the host path, |d| and the gradient turned with it
        negative = distance.signbit() if view.library == "torch" else __import__("cupy").signbit(distance)
        distance[negative] = -distance[negative]
        gradient[negative] = -gradient[negative]
    if differentiable and view.library == "torch" and _library(points) == "torch":
        distance = _ExactDistance.apply(points, distance.clone(), gradient)
    return DeviceQueryResult(view.result(distance), view.result(gradient), view.result(triangle), sdf.sign, sdf.sampler)


def _make_autograd():
    try:
        import torch
    except ImportError:
        return None

    class ExactDistance(torch.autograd.Function):
        """distance(points) with d distance / d points = the exact gradient."""

        @staticmethod
        def forward(ctx, points, distance, gradient):
            ctx.save_for_backward(gradient)
            ctx.points_dtype = points.dtype
            return distance

        @staticmethod
        def backward(ctx, grad_distance):
            (gradient,) = ctx.saved_tensors
            return (grad_distance[:, None] * gradient).to(ctx.points_dtype), None, None

    return ExactDistance


class _LazyAutograd:
    def __init__(self):
        self.function = None

    def apply(self, *args):
        if self.function is None:
            self.function = _make_autograd()
        return self.function.apply(*args)


_ExactDistance = _LazyAutograd()


def install(core):
    """Routes SDF.query, query and sdf to the device path for GPU points."""
    host_query, host_module_query, host_sdf = core.SDF.query, core.query, core.sdf

    def sdf_query(self, points, winding=False, progress=None, differentiable=False):
        if is_device_array(points):
            if winding:
                raise ValueError("winding=True needs host points (a NumPy array); GPU points give distance, gradient "
                                 "and triangle")
            return query_device(self, points, differentiable)
        return host_query(self, points, winding=winding, progress=progress)

    sdf_query.__doc__ = host_query.__doc__ + (
        "\n\nGPU points (a PyTorch CUDA tensor, a CuPy array, a JAX GPU array) stay on the GPU: the result is a "
        "DeviceQueryResult of arrays of the same library on the same device (sdf_lattices._gpu); "
        "differentiable=True (PyTorch) gives a distance that autograd differentiates with the exact gradient.")

    def module_query(mesh, points, progress=None, winding=False, **sampler):
        if is_device_array(points):
            return sdf_query(core.SDF(mesh, **sampler), points, winding=winding, progress=progress)
        return host_module_query(mesh, points, progress=progress, winding=winding, **sampler)

    module_query.__doc__ = host_module_query.__doc__ + "\n\nGPU points stay on the GPU (see SDF.query)."

    def module_sdf(mesh, points, progress=None, **sampler):
        if is_device_array(points):
            return sdf_query(core.SDF(mesh, **sampler), points, progress=progress).distance
        return host_sdf(mesh, points, progress=progress, **sampler)

    module_sdf.__doc__ = host_sdf.__doc__ + "\n\nGPU points stay on the GPU: the distances are an array of their library."

    core.SDF.query = sdf_query
    return module_query, module_sdf


__all__ = ["DeviceQueryResult", "is_device_array", "query_device", "install"]
