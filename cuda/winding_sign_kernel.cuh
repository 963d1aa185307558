/// @file winding_sign_kernel.cuh
/// @brief The winding-number sign in the CUDA finalize kernels (sign mode "winding",
/// core/sampling/sampler_sign.h): the fast winding number (kernels/winding/
/// fast_winding_number.h, Barill et al. 2018) over the uploaded BVH and its moments, at the
/// CPU WindingSign's accuracy, decides the side; distance and gradient keep their exact
/// magnitude and direction (with_sign).
#pragma once

#include "kernels/winding/fast_winding_number.h"
#include "kernels/winding/with_sign.h"

namespace sdf::cuda {

/// Device pointers of a winding BVH; no nodes = pseudonormal mode, samples left as they are.
struct WindingSignView {
    WindingView<double> view{};
    WindingAccuracy<double> accuracy{};
    SDF_CPU_GPU bool enabled() const { return view.nodes != nullptr; }
};

/// `s` (evaluated at p) with the side w(p) > 1/2, as WindingSign::inside on the CPU.
__device__ inline SignedDistanceSample<double> apply_winding_sign(const WindingSignView& w, const SignedDistanceSample<double>& s,
                                                                  const Vec3d& p) {
    return w.enabled() ? with_sign(s, fast_winding_number(w.view, p, w.accuracy).value > 0.5) : s;
}

}  // namespace sdf::cuda
