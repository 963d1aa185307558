/// @file certified_winding_packet.h
/// @brief The certified estimates (certified_winding.h) of K neighbouring points in one BVH
/// traversal, each lane bit for bit what certified_winding_number() gives its point alone,
/// and the certified ladder over a packet: each stage one traversal for the lanes still
/// undecided. CPU only. Why the bits are the same: fast_winding_packet.h (the union of the
/// lanes' opened nodes in depth-first order; each lane adds the same terms, computed by the
/// same functions, in its own order; lanes that do not take a term are left untouched).
#pragma once

#include <cstdint>

#include "kernels/winding/certified_winding.h"

namespace sdf {

/// The certified estimate of the lanes in `lanes` (1: evaluate) into value/bound.
template <int K>
inline void certified_winding_numbers_packet(const WindingView<double>& v, const Vec3d* p, const int64_t* lanes,
                                             const WindingAccuracy<double>& acc, double* value_out, double* bound_out) {
    WindingRounding rnd[K];
    CertifiedSum sum[K];
    int32_t stack_node[kBvhMaxDepth + 1];
    int64_t stack_lanes[kBvhMaxDepth + 1][K];
    int64_t any = 0;
    for (int k = 0; k < K; ++k) {
        rnd[k] = winding_rounding(v, p[k]);
        stack_lanes[0][k] = lanes[k];
        any |= lanes[k];
    }
    stack_node[0] = 0;
    int top = any ? 1 : 0;
    while (top > 0) {
        --top;
        const int32_t node = stack_node[top];
        int64_t active[K];
        for (int k = 0; k < K; ++k) active[k] = stack_lanes[top][k];
        const BvhNode& n = v.nodes[node];
        for (int c = 0; c < 2; ++c) {
            const WindingMoments<double>& m = v.moments[node].child[c];
            const double limit = far_limit(m, acc);
            int64_t open[K];
            int64_t any_open = 0;
            for (int k = 0; k < K; ++k) {
                open[k] = 0;
                if (!active[k]) continue;
                const Vec3d y = m.center - p[k];
                const double d2 = length_squared(y);
                if (d2 > limit) {
                    double term, bound;
                    certified_far_term(m, y, d2, acc.order, rnd[k], term, bound);
                    sum[k].add(term, bound);
                } else {
                    open[k] = 1;
                    any_open = 1;
                }
            }
            if (!any_open) continue;
            if (bvh_child_is_leaf(n, c)) {
                for (int k = 0; k < K; ++k)
                    if (open[k]) certified_leaf(sum[k], v, n.ref[c], n.count[c], p[k]);
            } else {
                SDF_DCHECK(top <= kBvhMaxDepth);
                stack_node[top] = n.ref[c];
                for (int k = 0; k < K; ++k) stack_lanes[top][k] = open[k];
                ++top;
            }
        }
    }
    for (int k = 0; k < K; ++k) {
        const WindingEstimate<double> e = certified_estimate(sum[k], rnd[k], 0);
        value_out[k] = e.value;
        bound_out[k] = e.error_bound;
    }
}

/// The certified sides of the first `count` lanes of p: certified_winding_side() of each,
/// bit for bit, with one traversal per stage for the lanes still undecided.
template <int K>
inline void certified_winding_sides_packet(const WindingView<double>& v, const Vec3d* p, int count,
                                           const WindingAccuracy<double>& acc, const WindingCertification& cert,
                                           WindingSide* side) {
    int64_t lanes[K];
    int left = 0;
    for (int k = 0; k < K; ++k) {
        lanes[k] = k < count;
        left += int(lanes[k]);
    }
    WindingAccuracy<double> stage_acc = acc;
    double value[K], bound[K];
    for (int stage = 0; stage <= cert.refinements && left > 0; ++stage) {
        if (stage > 0) stage_acc.beta *= cert.refine_factor;
        certified_winding_numbers_packet<K>(v, p, lanes, stage_acc, value, bound);
        for (int k = 0; k < K; ++k)
            if (lanes[k] && winding_decides(WindingEstimate<double>{value[k], bound[k], 0})) {
                side[k] = {value[k] > 0.5, stage == 0 ? WindingStage::Fast : WindingStage::Refined};
                lanes[k] = 0;
                --left;
            }
    }
    for (int k = 0; k < K; ++k)
        if (lanes[k]) {
            const WindingEstimate<double> e = certified_winding_direct(v, p[k]);
            side[k] = winding_decides(e) ? WindingSide{e.value > 0.5, WindingStage::Direct} : WindingSide{false, WindingStage::Tie};
        }
}

}  // namespace sdf
