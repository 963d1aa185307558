// DeviceWinding's float copy of the winding moments (cuda/device_winding.h).
#include "cuda/device_winding.h"

#include <cstdlib>

#include "cuda/cuda_check.h"

namespace sdf::cuda {
namespace {

__global__ void round_moments_kernel(const WindingNode<double>* moments, int n, WindingNode<float>* out) {
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) out[i] = rounded_to_float(moments[i]);
}

}  // namespace

bool DeviceWinding::float_first() {
    static const bool on = std::getenv("SDF_CUDA_WINDING_DOUBLE") == nullptr;
    return on;
}

void DeviceWinding::round_moments(cudaStream_t stream) {
    view_.float_moments = nullptr;
    if (!float_first() || view_.view.num_nodes <= 0) return;
    const int n = view_.view.num_nodes;
    float_moments_.allocate(size_t(n));
    if (stream != 0) CUDA_CHECK(cudaStreamSynchronize(0));  // the allocation is stream 0's
    round_moments_kernel<<<(n + 255) / 256, 256, 0, stream>>>(view_.view.moments, n, float_moments_.get());
    CUDA_CHECK_LAUNCH("round_moments");
    view_.float_moments = float_moments_.get();
}

}  // namespace sdf::cuda
