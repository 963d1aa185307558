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
exact gradient (d distance / d point = gradient), and with respect to the mesh's vertices
when they are a torch tensor that requires grad (sdf_lattices._torch, on the CPU too).
dtype="float32" rounds the float64 results to float32 at the end. query_batch runs the
searches of many SDFs in one native call.
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

    def cast(self, array, dtype):
        """`array` as `dtype` ("float32"), on its device."""
        if self.library == "torch":
            import torch
            return array.to(getattr(torch, dtype))
        return array.astype(dtype)

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
    """Results of a query of GPU points (or of torch points with differentiable=True, on the
    CPU too), arrays of the input's library on its device, in input order: distance (N,)
    float64, gradient (N, 3) float64 (both float32 with dtype="float32"), triangle (N,) int32
    (the caller's face order); sign and sampler as in QueryResult. Closest points, barycentric
    coordinates and winding numbers are host-path outputs (pass a NumPy array for them)."""

    def __init__(self, distance, gradient, triangle, sign, sampler):
        self.distance, self.gradient, self.triangle = distance, gradient, triangle
        self.sign, self.sampler = sign, sampler

    def __len__(self):
        return int(self.distance.shape[0])

    def __repr__(self):
        return "<sdf_lattices.DeviceQueryResult: %d points on %s, sign '%s', sampler '%s'>" % (
            len(self), getattr(self.distance, "device", "the GPU"), self.sign, self.sampler)


def _check_backend(sdf):
    if sdf.backend != "cuda":
        raise ValueError("points on a GPU need an SDF built with backend='cuda' (or 'auto' on a machine with a GPU); "
                         "this one's sampler is '%s'" % sdf.sampler)


def _outputs(view):
    n = view.count
    return view.empty((n,), "float64"), view.empty((n, 3), "float64"), view.empty((n,), "int32")


def _call(view, distance, gradient, triangle):
    """The numbers of one device query (SDF._query_device's arguments after the SDF)."""
    return (view.pointer, view.count, view.float32, view.row, view.column, view.device, view.stream,
            view.pointer_of(distance), view.pointer_of(gradient), view.pointer_of(triangle))


def _finish(sdf, view, points, distance, gradient, triangle, differentiable, dtype):
    """Unsigned distance, autograd and the output dtype of one device query's float64 results."""
    if sdf.sign == "none":  # unsigned: as the host path, |d| and the gradient turned with it
        negative = distance.signbit() if view.library == "torch" else __import__("cupy").signbit(distance)
        distance[negative] = -distance[negative]
        gradient[negative] = -gradient[negative]
    if differentiable:
        from . import _torch
        distance = _torch.differentiable_distance(sdf, points, distance, gradient, triangle, None, dtype)
    elif dtype == "float32":
        distance = view.cast(distance, "float32")
    if dtype == "float32":
        gradient = view.cast(gradient, "float32")
    return DeviceQueryResult(view.result(distance), view.result(gradient), view.result(triangle), sdf.sign, sdf.sampler)


def query_device(sdf, points, differentiable=False, dtype="float64"):
    """The device path of SDF.query for GPU points (see the module's doc)."""
    _check_backend(sdf)
    view = _View(points)
    distance, gradient, triangle = _outputs(view)
    if view.count > 0:
        sdf._query_device(*_call(view, distance, gradient, triangle))
    return _finish(sdf, view, points, distance, gradient, triangle, differentiable, dtype)


def query_device_batch(core, sdfs, points, differentiable=False, dtype="float64"):
    """query_batch of GPU points: every SDF's search in one native call (SDF._query_device's
    work for each, in turn, with the GIL released once), the outputs allocated before it."""
    for s in sdfs:
        _check_backend(s)
    views = [_View(p) for p in points]
    outputs = [_outputs(v) for v in views]
    core._query_device_batch(sdfs, [_call(v, *o) for v, o in zip(views, outputs)])
    return [_finish(s, v, p, *o, differentiable, dtype) for s, v, p, o in zip(sdfs, views, points, outputs)]


def _dtype_name(dtype):
    import numpy as np
    try:
        name = np.dtype(dtype).name
    except TypeError:
        name = None
    if name not in ("float32", "float64"):
        raise ValueError('dtype: expected "float64" or "float32", got %r' % (dtype,))
    return name


def _refuse_differentiable(points):
    raise TypeError("differentiable=True: points must be a torch tensor (on the CPU or a CUDA device) for autograd to "
                    "differentiate; got %s.%s" % (type(points).__module__, type(points).__qualname__))


def _host_differentiable(sdf, points, result, dtype):
    """A host QueryResult (float64) of torch CPU points as torch tensors, the distance
    differentiable (sdf_lattices._torch)."""
    import torch
    from . import _torch
    distance, gradient = torch.as_tensor(result.distance), torch.as_tensor(result.gradient)
    triangle = torch.as_tensor(result.triangle)
    barycentric = torch.as_tensor(result.barycentric) if _torch.wants_vertices(sdf) else None
    distance = _torch.differentiable_distance(sdf, points, distance, gradient, triangle, barycentric, dtype)
    return DeviceQueryResult(distance, gradient.to(getattr(torch, dtype)), triangle, result.sign, result.sampler)


def install(core):
    """Routes SDF.query, query, sdf and query_batch to the device path for GPU points and to
    autograd for torch tensors (differentiable=True); SDF remembers torch vertex tensors."""
    from . import _torch
    host_query, host_module_query, host_sdf = core.SDF.query, core.query, core.sdf
    host_batch, host_init, host_refit = core.query_batch, core.SDF.__init__, core.SDF.refit

    def sdf_init(self, mesh, **sampler):
        host_init(self, mesh, **sampler)
        _torch.remember_vertices(self, _torch.vertex_tensor_of(mesh))

    sdf_init.__doc__ = host_init.__doc__

    def refit(self, new_vertices):
        refitted = host_refit(self, _torch.as_numpy(new_vertices))
        _torch.remember_vertices(refitted, new_vertices if _torch.is_tensor(new_vertices) else None)
        return refitted

    refit.__doc__ = host_refit.__doc__ + (
        "\n\nnew_vertices may be a torch tensor (any device): with differentiable=True, queries of the result give "
        "gradients with respect to it when it requires grad.")

    def sdf_query(self, points, winding=False, progress=None, differentiable=False, dtype="float64"):
        dtype = _dtype_name(dtype)
        if is_device_array(points):
            if winding:
                raise ValueError("winding=True needs host points (a NumPy array); GPU points give distance, gradient "
                                 "and triangle")
            if differentiable and _library(points) != "torch":
                _refuse_differentiable(points)
            return query_device(self, points, differentiable, dtype)
        if differentiable:
            if not _torch.is_tensor(points):
                _refuse_differentiable(points)
            if winding:
                raise ValueError("winding=True: winding numbers are a QueryResult output; differentiable=True returns "
                                 "distance, gradient and triangle tensors (query the winding numbers without it)")
            result = host_query(self, _torch.as_numpy(points), progress=progress)
            return _host_differentiable(self, points, result, dtype)
        return host_query(self, _torch.as_numpy(points), winding=winding, progress=progress, dtype=dtype)

    sdf_query.__doc__ = host_query.__doc__ + (
        "\n\nGPU points (a PyTorch CUDA tensor, a CuPy array, a JAX GPU array) stay on the GPU: the result is a "
        "DeviceQueryResult of arrays of the same library on the same device (sdf_lattices._gpu). "
        "differentiable=True takes PyTorch tensors on the CPU or a CUDA device and returns a DeviceQueryResult of "
        "tensors on that device whose distance autograd differentiates exactly: with respect to the points (the "
        "gradient) and, when the SDF's mesh came from a (vertices, faces) pair whose vertices are a torch tensor that "
        "requires grad, with respect to those vertices (-barycentric_k * gradient on the closest face's corners; "
        "sdf_lattices._torch says where this is exact).")

    def module_query(mesh, points, progress=None, winding=False, differentiable=False, dtype="float64", **sampler):
        if differentiable or is_device_array(points) or _torch.is_tensor(points):
            return sdf_query(core.SDF(mesh, **sampler), points, winding=winding, progress=progress,
                             differentiable=differentiable, dtype=dtype)
        return host_module_query(mesh, points, progress=progress, winding=winding, dtype=dtype, **sampler)

    module_query.__doc__ = host_module_query.__doc__ + (
        "\n\nGPU points stay on the GPU; torch tensors and differentiable=True as in SDF.query.")

    def module_sdf(mesh, points, progress=None, differentiable=False, dtype="float64", **sampler):
        if differentiable or is_device_array(points) or _torch.is_tensor(points):
            return sdf_query(core.SDF(mesh, **sampler), points, progress=progress, differentiable=differentiable,
                             dtype=dtype).distance
        return host_sdf(mesh, points, progress=progress, dtype=dtype, **sampler)

    module_sdf.__doc__ = host_sdf.__doc__ + (
        "\n\nGPU points stay on the GPU: the distances are an array of their library. differentiable=True (torch "
        "points, CPU or CUDA): a tensor that autograd differentiates with respect to the points and, when mesh is "
        "(vertices, faces) with a torch vertex tensor that requires grad, the vertices (see SDF.query).")

    def query_batch(sdfs, points, progress=None, dtype="float64", differentiable=False):
        dtype = _dtype_name(dtype)
        if not isinstance(points, (list, tuple)) or not isinstance(sdfs, (list, tuple)):
            return host_batch(sdfs, points, progress=progress, dtype=dtype)  # its TypeError names the argument
        on_device = [is_device_array(p) for p in points]
        if any(on_device):
            if not all(on_device):
                raise ValueError("query_batch: points[%d] is on a GPU and points[%d] is not; give all on GPUs or all on "
                                 "the host" % (on_device.index(True), on_device.index(False)))
            if len(sdfs) != len(points):
                raise ValueError("query_batch: expected as many point arrays as SDFs, got %d point arrays for %d SDFs"
                                 % (len(points), len(sdfs)))
            for p in points if differentiable else ():
                if _library(p) != "torch":
                    _refuse_differentiable(p)
            return query_device_batch(core, list(sdfs), list(points), differentiable, dtype)
        if differentiable:
            for p in points:
                if not _torch.is_tensor(p):
                    _refuse_differentiable(p)
            results = host_batch(sdfs, [_torch.as_numpy(p) for p in points], progress=progress)
            return [_host_differentiable(s, p, r, dtype) for s, p, r in zip(sdfs, points, results)]
        return host_batch(sdfs, [_torch.as_numpy(p) for p in points], progress=progress, dtype=dtype)

    query_batch.__doc__ = host_batch.__doc__ + (
        "\n\ndifferentiable=True (torch tensors, CPU or CUDA): DeviceQueryResults whose distances autograd "
        "differentiates, as SDF.query's.")

    core.SDF.__init__ = sdf_init
    core.SDF.query = sdf_query
    core.SDF.refit = refit
    return module_query, module_sdf, query_batch


__all__ = ["DeviceQueryResult", "is_device_array", "query_device", "query_device_batch", "install"]
