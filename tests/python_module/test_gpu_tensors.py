"""GPU tensors in and out (sdf_lattices._gpu): PyTorch and CuPy points on a CUDA device give
results of the same library on the same device, equal to the host path's bit for bit, without
moving or copying the points (their device pointer and values are unchanged); float32 and
strided views; unsigned distances; autograd with the exact gradient. Skipped where neither
library, or no GPU, or no CUDA backend is present."""
import time

import numpy as np
import pytest

import sdf_lattices as sl


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


pytestmark = pytest.mark.skipif(not sl.cuda_available(), reason="no CUDA device or no CUDA backend in this build")


@pytest.fixture(scope="module")
def bound():
    return sl.SDF(sl.load_mesh("shape:soccer_ball"), backend="cuda")


def _points(n, seed=5):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.3, 1.3, size=(n, 3))


def _expect_equal_to_host(bound, device_result, host_points, to_numpy):
    host = bound.query(host_points)
    assert np.array_equal(to_numpy(device_result.distance), host.distance)
    assert np.array_equal(to_numpy(device_result.gradient), host.gradient)
    assert np.array_equal(to_numpy(device_result.triangle), host.triangle)
    assert device_result.sign == host.sign and device_result.sampler == host.sampler


def test_torch_points_stay_on_the_device_and_equal_the_host_path(bound):
    torch = _torch_cuda()
    if torch is None:
        pytest.skip("PyTorch with CUDA is not installed")
    host = _points(20011)
    points = torch.from_numpy(host).cuda()
    before = points.clone()
    pointer = points.data_ptr()
    r = bound.query(points)
    assert isinstance(r, sl.DeviceQueryResult)
    assert r.distance.device == points.device and r.gradient.device == points.device and r.triangle.device == points.device
    assert r.distance.dtype == torch.float64 and r.triangle.dtype == torch.int32 and tuple(r.gradient.shape) == (20011, 3)
    assert points.data_ptr() == pointer and torch.equal(points, before)  # read in place, not copied or changed
    _expect_equal_to_host(bound, r, host, lambda a: a.cpu().numpy())
    # float32, as a strided view (the first three columns of an N x 4 tensor)
    padded = torch.from_numpy(np.hstack([host, np.ones((len(host), 1))]).astype(np.float32)).cuda()
    view = padded[:, :3]
    assert not view.is_contiguous()
    _expect_equal_to_host(bound, bound.query(view), host.astype(np.float32).astype(np.float64), lambda a: a.cpu().numpy())
    # the module's functions route GPU points too, and a stream of the caller's orders the work
    stream = torch.cuda.Stream()
    with torch.cuda.stream(stream):
        shifted = points * 1.0 + 0.0
        d = sl.sdf(bound.mesh, shifted, backend="cuda")
    assert d.device == points.device
    assert np.array_equal(d.cpu().numpy(), bound.query(host).distance)


def test_torch_unsigned_and_autograd(bound):
    torch = _torch_cuda()
    if torch is None:
        pytest.skip("PyTorch with CUDA is not installed")
    host = _points(3001, seed=8)
    unsigned = sl.SDF(bound.mesh, backend="cuda", sign="none")
    r = unsigned.query(torch.from_numpy(host).cuda())
    h = unsigned.query(host)
    assert np.array_equal(r.distance.cpu().numpy(), h.distance)
    assert np.array_equal(r.gradient.cpu().numpy(), h.gradient)
    points = torch.from_numpy(host).cuda().requires_grad_()
    r = bound.query(points, differentiable=True)
    r.distance.sum().backward()
    assert torch.equal(points.grad, r.gradient)


def test_cupy_points_stay_on_the_device_and_equal_the_host_path(bound):
    cupy = _cupy_cuda()
    if cupy is None:
        pytest.skip("CuPy with a GPU is not installed")
    host = _points(7777, seed=9)
    points = cupy.asarray(host)
    pointer = points.data.ptr
    r = bound.query(points)
    assert isinstance(r.distance, cupy.ndarray) and r.distance.device.id == points.device.id
    assert points.data.ptr == pointer
    _expect_equal_to_host(bound, r, host, cupy.asnumpy)
    column_major = cupy.asfortranarray(points)
    _expect_equal_to_host(bound, bound.query(column_major), host, cupy.asnumpy)


def test_gpu_points_errors_are_clear(bound):
    torch = _torch_cuda()
    if torch is None:
        pytest.skip("PyTorch with CUDA is not installed")
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        bound.query(torch.zeros((10, 2), device="cuda"))
    with pytest.raises(TypeError, match="float32 or float64"):
        bound.query(torch.zeros((10, 3), dtype=torch.int32, device="cuda"))
    bad = torch.zeros((10, 3), dtype=torch.float64, device="cuda")
    bad[6, 1] = float("nan")
    with pytest.raises(ValueError, match="query points: row 6 "):
        bound.query(bad)
    with pytest.raises(ValueError, match="winding"):
        bound.query(torch.zeros((4, 3), device="cuda"), winding=True)
    cpu_bound = sl.SDF(bound.mesh, backend="cpu")
    with pytest.raises(ValueError, match="backend='cuda'"):
        cpu_bound.query(torch.zeros((4, 3), device="cuda"))


def test_gpu_points_timing_is_reported(bound, capsys):
    """Not a timed assertion: prints the wall time of one call on 1M points beside the host path."""
    torch = _torch_cuda()
    if torch is None:
        pytest.skip("PyTorch with CUDA is not installed")
    host = _points(1 << 20, seed=12)
    points = torch.from_numpy(host).cuda()
    bound.query(points)  # warm-up
    torch.cuda.synchronize()
    t0 = time.perf_counter()
    r = bound.query(points)
    torch.cuda.synchronize()
    device_seconds = time.perf_counter() - t0
    t0 = time.perf_counter()
    bound.query(host)
    host_seconds = time.perf_counter() - t0
    with capsys.disabled():
        print("\n1M points on %s: GPU tensors in and out %.4f s, NumPy in and out (same sampler) %.4f s"
              % (torch.cuda.get_device_name(), device_seconds, host_seconds))
    assert len(r) == 1 << 20
