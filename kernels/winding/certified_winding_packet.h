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

namespace detail {

/// Adds the leaf's solid angles (slots [first, first + count)) with their rounding bounds to
/// the lanes in `open`, as certified_leaf() does for one point: N, D and S for all lanes in a
/// vector loop, atan2 and the bound (hypot) the scalar library calls of the open lanes.
template <int K>
inline void add_certified_leaf(const WindingView<double>& v, int32_t first, int32_t count, const double* px,
                               const double* py, const double* pz, const int64_t* open, double* value, double* bound) {
    double s[K], e[K];
    for (int k = 0; k < K; ++k) s[k] = e[k] = 0.0;
    for (int32_t slot = first; slot < first + count; ++slot) {
        const Int3 t = v.triangles[v.triangle_index[slot]];
        const Vec3d v0 = v.vertices[t.x], v1 = v.vertices[t.y], v2 = v.vertices[t.z];
        double numerator[K], denominator[K], S[K];
#pragma omp simd
        for (int k = 0; k < K; ++k)
            certified_solid_angle_terms(Vec3d(px[k], py[k], pz[k]), v0, v1, v2, numerator[k], denominator[k], S[k]);
        for (int k = 0; k < K; ++k)
            if (open[k]) {
                const double err = solid_angle_rounding(numerator[k], denominator[k], S[k]);
                s[k] += 2.0 * atan2(numerator[k], denominator[k]);
                e[k] += err + kWindingUnitRoundoff * fabs(s[k]);
            }
    }
    for (int k = 0; k < K; ++k)
        if (open[k]) {
            CertifiedSum sum{value[k], bound[k]};
            add_solid_angles(sum, s[k], e[k]);
            value[k] = sum.value;
            bound[k] = sum.bound;
        }
}

}  // namespace detail

/// The certified estimate of the lanes in `lanes` (1: evaluate) into value/bound, at
/// expansion order `Order` (a constant, so that the far-field lane loop has no branch and
/// vectorises, as fast_winding_packet.h's), on local copies of the points and sums.
template <int K, int Order>
inline void certified_winding_numbers_packet_at(const WindingView<double>& v, const Vec3d* p, const int64_t* lanes,
                                                const WindingAccuracy<double>& acc, double* value_out, double* bound_out) {
    double px[K], py[K], pz[K], scale[K], value[K], bound[K];
    int32_t stack_node[kBvhMaxDepth + 1];
    int64_t stack_lanes[kBvhMaxDepth + 1][K];
    int64_t any = 0;
    const double n_factor = winding_rounding(v, p[0]).n_factor;  // the mesh's: the same for every lane
    for (int k = 0; k < K; ++k) {
        px[k] = p[k].x;
        py[k] = p[k].y;
        pz[k] = p[k].z;
        scale[k] = winding_rounding(v, p[k]).scale;
        value[k] = bound[k] = 0.0;
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
            int64_t add[K], open[K];
            int64_t any_add = 0, any_open = 0;
#pragma omp simd reduction(| : any_add, any_open)
            for (int k = 0; k < K; ++k) {
                const Vec3d y = m.center - Vec3d(px[k], py[k], pz[k]);
                const int64_t far = int64_t(length_squared(y) > limit);
                add[k] = active[k] & far;
                open[k] = active[k] & (far ^ 1);
                any_add |= add[k];
                any_open |= open[k];
            }
            if (any_add) {
#pragma omp simd
                for (int k = 0; k < K; ++k) {
                    const Vec3d y = m.center - Vec3d(px[k], py[k], pz[k]);
                    double term, term_bound;
                    certified_far_term(m, y, length_squared(y), Order, WindingRounding{n_factor, scale[k]}, term, term_bound);
                    // CertifiedSum::add, selected (never adding zero: -0 would become +0)
                    const double sum = value[k] + term;
                    const double sum_bound = bound[k] + (term_bound + kWindingUnitRoundoff * fabs(sum));
                    value[k] = add[k] ? sum : value[k];
                    bound[k] = add[k] ? sum_bound : bound[k];
                }
            }
            if (!any_open) continue;
            if (bvh_child_is_leaf(n, c)) {
                detail::add_certified_leaf<K>(v, n.ref[c], n.count[c], px, py, pz, open, value, bound);
            } else {
                SDF_DCHECK(top <= kBvhMaxDepth);
                stack_node[top] = n.ref[c];
                for (int k = 0; k < K; ++k) stack_lanes[top][k] = open[k];
                ++top;
            }
        }
    }
    for (int k = 0; k < K; ++k) {
        const WindingEstimate<double> e = certified_estimate(CertifiedSum{value[k], bound[k]}, WindingRounding{n_factor, scale[k]}, 0);
        value_out[k] = e.value;
        bound_out[k] = e.error_bound;
    }
}

/// The certified estimate of the lanes in `lanes` (1: evaluate) into value/bound: lane k
/// equals certified_winding_number(v, p_k, acc) bit for bit.
template <int K>
inline void certified_winding_numbers_packet(const WindingView<double>& v, const Vec3d* p, const int64_t* lanes,
                                             const WindingAccuracy<double>& acc, double* value_out, double* bound_out) {
    if (acc.order >= 2) certified_winding_numbers_packet_at<K, 2>(v, p, lanes, acc, value_out, bound_out);
    else certified_winding_numbers_packet_at<K, 1>(v, p, lanes, acc, value_out, bound_out);
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
