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

/// The fast winding number of every lane's point, fast_winding_number(v, p, acc).value bit for
/// bit, found by the whole warp in one traversal: the stack is the warp's, each stacked node
/// carries the mask of the lanes that opened it, and each node's moments are read once for
/// the warp. A lane adds the same terms by the same formulas (far_field(),
/// leaf_winding_number()) in the same order as its own traversal would: its opened nodes form
/// a subtree closed under ancestors, and the depth-first order (children 0 then 1, last pushed
/// first popped) restricted to that subtree is the subtree's own. Neighbouring points (a
/// lattice row, Morton-sorted points) open nearly the same nodes, so the warp walks about one
/// point's tree instead of 32 divergent ones. Every lane of the warp must call it; a lane
/// without a point passes wants = false (and gets 0).
__device__ inline double warp_fast_winding_value(const WindingView<double>& v, const Vec3d& p, bool wants,
                                                 const WindingAccuracy<double>& acc) {
    constexpr unsigned kWarp = 0xffffffffu;
    const unsigned lane_bit = 1u << (threadIdx.x & 31u);
    double value = 0.0;
    int32_t stack_node[kBvhMaxDepth + 1];
    unsigned stack_lanes[kBvhMaxDepth + 1];
    stack_lanes[0] = __ballot_sync(kWarp, wants);
    if (stack_lanes[0] == 0) return value;
    stack_node[0] = 0;
    int top = 1;
    while (top > 0) {  // warp-uniform: top, the stack and every ballot are the same in all lanes
        --top;
        const int32_t node = stack_node[top];
        const bool active = (stack_lanes[top] & lane_bit) != 0;
        const BvhNode& n = v.nodes[node];
        for (int c = 0; c < 2; ++c) {
            bool open = false;
            if (active) {
                double term, bound;
                if (far_field(v.moments[node].child[c], p, acc, term, bound)) value += term;
                else open = true;
            }
            const unsigned opened = __ballot_sync(kWarp, open);
            if (opened == 0) continue;
            if (bvh_child_is_leaf(n, c)) {
                if (open) value += leaf_winding_number(v, n.ref[c], n.count[c], p);
            } else {
                SDF_DCHECK(top <= kBvhMaxDepth);
                stack_node[top] = n.ref[c];
                stack_lanes[top] = opened;
                ++top;
            }
        }
    }
    return value;
}

}  // namespace sdf::cuda
