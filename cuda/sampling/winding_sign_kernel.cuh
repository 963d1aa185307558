/// @file winding_sign_kernel.cuh
/// @brief The winding-number sign in the CUDA finalize kernels (sign mode "winding",
/// core/sampling/sampler_sign.h): the certified side of 1/2 of the exact winding number
/// (kernels/winding/certified_winding.h: the fast winding number of Barill et al. 2018 over
/// the uploaded BVH and its moments with its rigorous bound, the stricter opening rules, the
/// direct sum, ties outside), the CPU WindingSign's ladder, so every tree gives the same
/// side; distance and gradient keep their exact magnitude and direction (with_sign). The
/// points are counted by how they were decided (`counts`, four counters).
#pragma once

#include "kernels/winding/certified_winding.h"
#include "kernels/winding/fast_winding_number.h"
#include "kernels/winding/surface_side.h"
#include "kernels/winding/with_sign.h"

namespace sdf::cuda {

/// Device pointers of a winding BVH; no nodes = pseudonormal mode, samples left as they are.
struct WindingSignView {
    WindingView<double> view{};
    WindingAccuracy<double> accuracy{};
    bool certify = true;  ///< false: the fast value's side (WindingSignOptions::certify)
    WindingCertification certification{};
    SurfaceSideView surface{};  ///< the sides from the closest triangle (device), or off
    unsigned long long* counts = nullptr;  ///< kWindingStages counters (device), or null
    SDF_CPU_GPU bool enabled() const { return view.nodes != nullptr; }
};

/// Counts one point decided at `stage` (one thread alone).
__device__ inline void count_winding_stage(const WindingSignView& w, WindingStage stage) {
    if (w.counts != nullptr) atomicAdd(&w.counts[int(stage)], 1ull);
}

/// The side of p, as WindingSign::side on the CPU (one thread alone).
__device__ inline WindingSide winding_side(const WindingSignView& w, const Vec3d& p) {
    if (!w.certify) return {fast_winding_number(w.view, p, w.accuracy).value > 0.5, WindingStage::Fast};
    return certified_winding_side(w.view, p, w.accuracy, w.certification);
}

/// `s` (evaluated at p) with the side of w(p) against 1/2, as WindingSign::inside on the CPU.
__device__ inline SignedDistanceSample<double> apply_winding_sign(const WindingSignView& w, const SignedDistanceSample<double>& s,
                                                                  const Vec3d& p) {
    if (!w.enabled()) return s;
    bool inside = false;
    if (w.certify && surface_side(w.surface, w.view, p, s.triangle, s.distance, inside)) {
        count_winding_stage(w, WindingStage::Surface);
        return with_sign(s, inside);
    }
    const WindingSide side = winding_side(w, p);
    count_winding_stage(w, side.stage);
    return with_sign(s, side.inside);
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

/// The certified estimate (certified_winding_number's value and bound, bit for bit) of every
/// lane's point, found by the whole warp in one traversal as warp_fast_winding_value() finds
/// the value. Every lane of the warp must call it; a lane without a point passes wants = false.
__device__ inline WindingEstimate<double> warp_certified_winding(const WindingView<double>& v, const Vec3d& p, bool wants,
                                                                 const WindingAccuracy<double>& acc) {
    constexpr unsigned kWarp = 0xffffffffu;
    const unsigned lane_bit = 1u << (threadIdx.x & 31u);
    const WindingRounding rnd = winding_rounding(v, p);
    CertifiedSum sum;
    int opened = 0;
    int32_t stack_node[kBvhMaxDepth + 1];
    unsigned stack_lanes[kBvhMaxDepth + 1];
    stack_lanes[0] = __ballot_sync(kWarp, wants);
    if (stack_lanes[0] == 0) return certified_estimate(sum, rnd, opened);
    stack_node[0] = 0;
    int top = 1;
    while (top > 0) {  // warp-uniform, as in warp_fast_winding_value()
        --top;
        const int32_t node = stack_node[top];
        const bool active = (stack_lanes[top] & lane_bit) != 0;
        opened += active;
        const BvhNode& n = v.nodes[node];
        for (int c = 0; c < 2; ++c) {
            bool open = false;
            if (active) {
                double term, bound;
                if (certified_far_field(v.moments[node].child[c], p, acc, rnd, term, bound)) sum.add(term, bound);
                else open = true;
            }
            const unsigned opened_lanes = __ballot_sync(kWarp, open);
            if (opened_lanes == 0) continue;
            if (bvh_child_is_leaf(n, c)) {
                if (open) certified_leaf(sum, v, n.ref[c], n.count[c], p);
            } else {
                SDF_DCHECK(top <= kBvhMaxDepth);
                stack_node[top] = n.ref[c];
                stack_lanes[top] = opened_lanes;
                ++top;
            }
        }
    }
    return certified_estimate(sum, rnd, opened);
}

/// The side of every lane's point (WindingSign::side's bits) with the warp's traversal for the
/// first evaluation; the lanes it does not decide refine alone (certified_winding_refine).
/// A lane whose side its closest triangle gave (`by_surface`, surface_side.h, counted as
/// `surface_stage`) passes it in `surface_inside` with wants = false. Counts the warp's points by stage, one atomic per stage and warp. Every lane must
/// call it.
__device__ inline bool warp_winding_inside(const WindingSignView& w, const Vec3d& p, bool wants, bool by_surface = false,
                                           bool surface_inside = false, WindingStage surface_stage = WindingStage::Surface) {
    constexpr unsigned kWarp = 0xffffffffu;
    WindingSide side{surface_inside, surface_stage};
    if (!by_surface) side.stage = WindingStage::Fast;
    if (!w.certify) {
        const double value = warp_fast_winding_value(w.view, p, wants, w.accuracy);
        if (wants) side.inside = value > 0.5;
    } else {
        const WindingEstimate<double> e = warp_certified_winding(w.view, p, wants, w.accuracy);
        if (wants) side.inside = e.value > 0.5;
        if (wants && !winding_decides(e)) side = certified_winding_refine(w.view, p, w.accuracy, w.certification);
    }
    __syncwarp(kWarp);
    if (w.counts != nullptr)
        for (int s = 0; s < kWindingStages; ++s) {
            const unsigned lanes = __ballot_sync(kWarp, (wants || by_surface) && int(side.stage) == s);
            if (lanes != 0 && (threadIdx.x & 31u) == 0) atomicAdd(&w.counts[s], (unsigned long long)__popc(lanes));
        }
    return side.inside;
}

}  // namespace sdf::cuda
