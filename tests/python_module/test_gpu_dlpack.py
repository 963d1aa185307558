"""GPU points given through DLPack (sdf_lattices._gpu): a JAX array on a CUDA device gives JAX
results on the same device, bit for bit the host path's, its buffer neither moved nor changed;
objects that offer only the DLPack protocol (__dlpack__, __dlpack_device__: a PyTorch tensor or
a CuPy array behind a wrapper without __cuda_array_interface__) are read in place the same way.
Each test skips where its library, a GPU or the CUDA backend is missing (JAX is not a Debian
package: it runs where it is installed, e.g. on the GPU machine)."""
import numpy as np
import pytest

import sdf_lattices as sl
from sdf_lattices import _gpu

pytestmark = pytest.mark.skipif(not sl.cuda_available(), reason="no CUDA device or no CUDA backend in this build")


def _jax_gpu():
    try:
        import jax
        devices = jax.devices("gpu")
    except Exception:  # not installed, or no GPU backend in this jaxlib
        return None, None
    return (jax, devices[0]) if devices else (None, None)


def _torch_cuda():
    try:
        import torch
    except ImportError:
        return None
    return torch if torch.cuda.is_available() else None


def _cupy_cuda():
    try:
        import cupy
        return cupy if cupy.cuda.runtime.getDeviceCount() > 0 else None
    except Exception:
        return None


@pytest.fixture(scope="module")
def bound():
    return sl.SDF(sl.load_mesh("shape:soccer_ball"), backend="cuda")


def _points(n, seed):
    return np.random.default_rng(seed).uniform(-1.3, 1.3, size=(n, 3))


def _expect_equal_to_host(bound, result, host_points, to_numpy):
    host = bound.query(host_points)
    assert np.array_equal(to_numpy(result.distance), host.distance)
    assert np.array_equal(to_numpy(result.gradient), host.gradient)
    assert np.array_equal(to_numpy(result.triangle), host.triangle)
    assert result.sign == host.sign and result.sampler == host.sampler


def _jax_devices(array):
    devices = array.devices() if callable(getattr(array, "devices", None)) else {array.device()}
    return set(devices)


@pytest.fixture
def jax_x64():
    """JAX with float64 arrays (its default is float32), restored afterwards."""
    jax, device = _jax_gpu()
    if jax is None:
        pytest.skip("JAX with a GPU is not installed")
    before = bool(getattr(jax.config, "jax_enable_x64", False))
    jax.config.update("jax_enable_x64", True)
    yield jax, device
    jax.config.update("jax_enable_x64", before)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_jax_points_in_and_out_on_the_device_equal_the_host_path(bound, jax_x64, dtype):
    jax, device = jax_x64
    host = _points(12007, seed=21).astype(dtype)
    points = jax.device_put(host, device)
    pointer = points.unsafe_buffer_pointer()
    r = bound.query(points)
    assert isinstance(r, sl.DeviceQueryResult)
    for a in (r.distance, r.gradient, r.triangle):
        assert isinstance(a, jax.Array) and _jax_devices(a) == {device}
    assert r.distance.dtype == np.float64 and r.triangle.dtype == np.int32 and r.gradient.shape == (12007, 3)
    assert points.unsafe_buffer_pointer() == pointer and np.array_equal(np.asarray(points), host)  # read in place
    _expect_equal_to_host(bound, r, host.astype(np.float64), np.asarray)
    d = sl.sdf(bound.mesh, points, backend="cuda")  # the one-liner routes JAX arrays too
    assert isinstance(d, jax.Array) and np.array_equal(np.asarray(d), np.asarray(r.distance))


class DLPackOnly:
    """An array seen only through the DLPack protocol (no __cuda_array_interface__)."""

    def __init__(self, array):
        self._array = array

    def __dlpack__(self, stream=None):
        return self._array.__dlpack__(stream=stream)

    def __dlpack_device__(self):
        return self._array.__dlpack_device__()


def _to_numpy(array):
    if type(array).__module__.split(".")[0] == "torch":
        return array.cpu().numpy()
    import cupy
    return cupy.asnumpy(array)


def _device_index(array):
    return array.device.index if type(array).__module__.split(".")[0] == "torch" else array.device.id


@pytest.mark.parametrize("library", ["torch", "cupy"])
def test_dlpack_protocol_objects_are_read_in_place(bound, library):
    module = _torch_cuda() if library == "torch" else _cupy_cuda()
    if module is None:
        pytest.skip("%s with a GPU is not installed" % library)
    host = _points(5003, seed=22)
    for dtype in (np.float64, np.float32):
        array = module.from_numpy(host.astype(dtype)).cuda() if library == "torch" else module.asarray(host.astype(dtype))
        before = _to_numpy(array).copy()
        wrapped = DLPackOnly(array)
        assert not hasattr(wrapped, "__cuda_array_interface__") and _gpu.is_device_array(wrapped)
        r = bound.query(wrapped)
        assert isinstance(r, sl.DeviceQueryResult)
        own = array.device.index if library == "torch" else array.device.id
        for a in (r.distance, r.gradient, r.triangle):
            assert type(a).__module__.split(".")[0] in ("torch", "cupy") and _device_index(a) == own
        assert np.array_equal(_to_numpy(array), before)
        _expect_equal_to_host(bound, r, host.astype(dtype).astype(np.float64), _to_numpy)
