/// @file fast_winding_packet.h
/// @brief The fast winding numbers of K neighbouring points in one BVH traversal (a packet),
/// each lane bit for bit the value fast_winding_number() gives its point alone. CPU only:
/// the lanes' arithmetic vectorises, atan2 stays the scalar library call.
///
/// Why the bits are the same: fast_winding_number() sums, in double, one term per child it
/// meets (a far-field value or a leaf's solid angles), in the order of a depth-first traversal
/// that looks at children 0 then 1 and pops the subtrees it opened last-in first-out. The
/// packet traversal does the same on the union of the lanes' opened nodes, with a lane mask
/// per stacked node. A lane's own nodes form a subtree closed under ancestors, and a
/// depth-first order restricted to such a subtree is that subtree's own depth-first order: so
/// each lane adds the same terms, computed by the same formulas (far_field_value(),
/// solid_angle_terms()), in the same order. Inactive lanes compute too (vectors) but their
/// sums are left untouched by selects, never by adding zero (which would turn -0 into +0).
/// Only the value is computed: the error bound does not change it.
#pragma once

#include <cmath>
#include <cstdint>

#include "kernels/winding/fast_winding_number.h"

namespace sdf {

namespace detail {

/// Adds the solid angles of leaf slots [first, first + count) over 4 pi to the lanes in `open`,
/// as leaf_winding_number() sums them for one point.
template <int K>
inline void add_leaf_winding(const WindingView<double>& v, int32_t first, int32_t count, const double* px,
                             const double* py, const double* pz, const int64_t* open, double* value) {
    double sum[K];
    for (int k = 0; k < K; ++k) sum[k] = 0.0;
    for (int32_t s = first; s < first + count; ++s) {
        const Int3 t = v.triangles[v.triangle_index[s]];
        const Vec3<double> v0 = v.vertices[t.x], v1 = v.vertices[t.y], v2 = v.vertices[t.z];
        double numerator[K], denominator[K];
#pragma omp simd
        for (int k = 0; k < K; ++k) solid_angle_terms(Vec3<double>(px[k], py[k], pz[k]), v0, v1, v2, numerator[k], denominator[k]);
        for (int k = 0; k < K; ++k)
            if (open[k]) sum[k] += 2.0 * std::atan2(numerator[k], denominator[k]);
    }
#pragma omp simd
    for (int k = 0; k < K; ++k) value[k] = open[k] ? value[k] + sum[k] * inverse_four_pi<double>() : value[k];
}

}  // namespace detail

/// The packet traversal at expansion order `Order` (a constant, so that the lane loop has no
/// branch and vectorises), on local copies of the points and sums (no aliasing to check).
template <int K, int Order>
inline void fast_winding_numbers_packet_at(const WindingView<double>& v, const double* px_in, const double* py_in,
                                           const double* pz_in, const WindingAccuracy<double>& acc, double* value_out) {
    double px[K], py[K], pz[K], value[K];
    int32_t stack_node[kBvhMaxDepth + 1];
    int64_t stack_lanes[kBvhMaxDepth + 1][K];  // the lanes that opened the stacked node
    for (int k = 0; k < K; ++k) {
        px[k] = px_in[k];
        py[k] = py_in[k];
        pz[k] = pz_in[k];
        value[k] = 0.0;
        stack_lanes[0][k] = 1;
    }
    stack_node[0] = 0;
    int top = 1;
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
                const Vec3<double> y = m.center - Vec3<double>(px[k], py[k], pz[k]);
                const int64_t far = int64_t(length_squared(y) > limit);
                add[k] = active[k] & far;
                open[k] = active[k] & (far ^ 1);
                any_add |= add[k];
                any_open |= open[k];
            }
            if (any_add) {
#pragma omp simd
                for (int k = 0; k < K; ++k) {
                    const Vec3<double> y = m.center - Vec3<double>(px[k], py[k], pz[k]);
                    const double d = std::sqrt(length_squared(y)), inv_d = 1.0 / d, inv_d3 = inv_d * inv_d * inv_d;
                    const double term = far_field_value(m, y, inv_d, inv_d3, Order);
                    value[k] = add[k] ? value[k] + term : value[k];
                }
            }
            if (!any_open) continue;
            if (bvh_child_is_leaf(n, c)) {
                detail::add_leaf_winding<K>(v, n.ref[c], n.count[c], px, py, pz, open, value);
            } else {
                SDF_DCHECK(top <= kBvhMaxDepth);
                stack_node[top] = n.ref[c];
                for (int k = 0; k < K; ++k) stack_lanes[top][k] = open[k];
                ++top;
            }
        }
    }
    for (int k = 0; k < K; ++k) value_out[k] = value[k];
}

/// The fast winding number (value only) of the K points (px, py, pz) into `value`: lane k
/// equals fast_winding_number(v, p_k, acc).value bit for bit.
template <int K>
inline void fast_winding_numbers_packet(const WindingView<double>& v, const double* px, const double* py, const double* pz,
                                        const WindingAccuracy<double>& acc, double* value) {
    if (acc.order >= 2) fast_winding_numbers_packet_at<K, 2>(v, px, py, pz, acc, value);
    else fast_winding_numbers_packet_at<K, 1>(v, px, py, pz, acc, value);
}

}  // namespace sdf
