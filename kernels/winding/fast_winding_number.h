/// @file fast_winding_number.h
/// @brief The generalized winding number over the project's BVH with the far-field
/// expansion of Barill et al., "Fast Winding Numbers for Soups and Clouds" (SIGGRAPH 2018),
/// and a rigorous bound on its error, written once for host and device.
///
/// Far field. A child whose ball (center p~, radius r; winding_moments.h) is farther than
/// beta * r from the query q (beta > 1, Barill's accuracy parameter) contributes its
/// Taylor expansion about p~ instead of its triangles' solid angles. With y = p~ - q,
///   order 1 (dipole):  w_1 = N . y / (4 pi |y|^3)
///   order 2:           w_2 = w_1 + (tr M / |y|^3 - 3 y^T M y / |y|^5) / (4 pi)
/// (Barill eq. 11-12 for the kernel (x - q) . n / |x - q|^3; the order-2 term is exact for
/// the linear Taylor term because the integral of (x - p~) over a triangle is a_i (c_i - p~)).
/// Children not far enough are opened; leaves not far enough are summed exactly.
///
/// Error bound. The kernel is g(y) = -D(1/|y|)[n], and for the Newtonian potential
/// |D^k (1/|y|)| <= k! / |y|^(k+1) as a symmetric k-linear form (the Legendre generating
/// function 1/|y - h| = sum |h|^k P_k(cos) / |y|^(k+1) with |P_k| <= 1, and a symmetric
/// form's norm is attained on its diagonal). That series converges for |h| < |y|, and so
/// does g's Taylor series about y = p~ - q, whose degree-k term is bounded by
/// (k + 1) |h|^k / d^(k+2) (d = |y|). With |h| = |x - p~| <= r and t = r / d = 1 / beta
/// at most, the terms left out after degree m - 1 (m = order) sum to at most
///   |error| <= A / (4 pi d^2) * sum_{k>=m} (k + 1) t^k = A t^m (m + 1 - m t) / (4 pi d^2 (1 - t)^2)
/// per accepted child, with A its unsigned area. The traversal adds these up over the
/// accepted children: |w_fast(q) - w(q)| <= bound(q), rounding aside (about 1e-15 per
/// term in double, 1e-7 in float). So the sign w > 1/2 of the fast value is certain
/// wherever |w_fast - 1/2| > bound.
#pragma once

#include "kernels/bvh/bvh_node.h"
#include "kernels/winding/solid_angle.h"
#include "kernels/winding/winding_moments.h"

namespace sdf {

/// Plain pointers to a BVH with its moments and the mesh's triangles, host or device.
template <typename T>
struct WindingView {
    const BvhNode* nodes = nullptr;
    const WindingNode<T>* moments = nullptr;   ///< one per node
    const int32_t* triangle_index = nullptr;   ///< BVH slot -> mesh triangle
    const Vec3<T>* vertices = nullptr;
    const Int3* triangles = nullptr;
    int num_nodes = 0;
    int num_triangles = 0;  ///< of the mesh: the direct sum's range and the rounding bounds' n
    T scale{};              ///< the mesh's largest |coordinate|, for the rounding bounds (certified_winding.h)
};

/// Accuracy of the fast evaluation: beta (> 1) and the expansion order (1 or 2).
template <typename T>
struct WindingAccuracy {
    T beta = T(2);   ///< Barill's default; larger is more accurate and slower
    int order = 2;
};

template <typename T>
struct WindingEstimate {
    T value{};        ///< the fast winding number
    T error_bound{};  ///< |value - exact| <= error_bound (rounding aside)
    int opened = 0;   ///< nodes opened (a cost figure)
};

/// The squared distance (beta r)^2 beyond which a child's expansion is used: q is far from it
/// when |p~ - q|^2 > far_limit.
template <typename T>
SDF_CPU_GPU SDF_INLINE T far_limit(const WindingMoments<T>& m, const WindingAccuracy<T>& acc) {
    return acc.beta * acc.beta * m.radius * m.radius;
}

/// The far-field value of one child at y = p~ - q (inv_d = 1 / |y|, inv_d3 = inv_d^3): the
/// one formula of far_field() and of the CPU's packet evaluation (fast_winding_packet.h).
template <typename T>
SDF_CPU_GPU SDF_INLINE T far_field_value(const WindingMoments<T>& m, const Vec3<T>& y, T inv_d, T inv_d3, int order) {
    T value = dot(m.normal_sum, y) * inv_d3;
    if (order >= 2) {
        const T* M = m.second;
        const T trace = M[0] + M[4] + M[8];
        const Vec3<T> My{M[0] * y.x + M[1] * y.y + M[2] * y.z, M[3] * y.x + M[4] * y.y + M[5] * y.z,
                         M[6] * y.x + M[7] * y.y + M[8] * y.z};
        value += trace * inv_d3 - T(3) * dot(y, My) * inv_d3 * inv_d * inv_d;
    }
    return value * inverse_four_pi<T>();
}

/// Far-field value and error bound of one child seen from q; false when q is not far enough.
template <typename T>
SDF_CPU_GPU SDF_INLINE bool far_field(const WindingMoments<T>& m, const Vec3<T>& q, const WindingAccuracy<T>& acc,
                                      T& value, T& bound) {
    const Vec3<T> y = m.center - q;
    const T d2 = length_squared(y);
    if (!(d2 > far_limit(m, acc))) return false;
    const T d = std::sqrt(d2), inv_d = T(1) / d, inv_d3 = inv_d * inv_d * inv_d;
    value = far_field_value(m, y, inv_d, inv_d3, acc.order);
    const T t = m.radius * inv_d, one_minus_t = T(1) - t;  // t < 1 / beta < 1
    const T scale = m.area * inv_d * inv_d / (one_minus_t * one_minus_t);
    bound = acc.order >= 2 ? scale * t * t * (T(3) - T(2) * t) : scale * t * (T(2) - t);
    bound *= inverse_four_pi<T>();
    return true;
}

/// Sum of the exact solid angles of the leaf's triangles (BVH slots [first, first + count)), over 4 pi.
template <typename T>
SDF_CPU_GPU SDF_INLINE T leaf_winding_number(const WindingView<T>& v, int32_t first, int32_t count, const Vec3<T>& q) {
    T sum = T(0);
    for (int32_t s = first; s < first + count; ++s) {
        const Int3 t = v.triangles[v.triangle_index[s]];
        sum += triangle_solid_angle(q, v.vertices[t.x], v.vertices[t.y], v.vertices[t.z]);
    }
    return sum * inverse_four_pi<T>();
}

/// The fast winding number of q with its error bound. beta = +infinity opens every node:
/// the exact sum, in BVH order.
template <typename T>
SDF_CPU_GPU WindingEstimate<T> fast_winding_number(const WindingView<T>& v, const Vec3<T>& q, const WindingAccuracy<T>& acc) {
    WindingEstimate<T> est;
    int32_t stack[kBvhMaxDepth + 1];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const int32_t node = stack[--top];
        ++est.opened;
        const BvhNode& n = v.nodes[node];
        for (int c = 0; c < 2; ++c) {
            T value, bound;
            if (far_field(v.moments[node].child[c], q, acc, value, bound)) {
                est.value += value;
                est.error_bound += bound;
            } else if (bvh_child_is_leaf(n, c)) {
                est.value += leaf_winding_number(v, n.ref[c], n.count[c], q);
            } else {
                SDF_DCHECK(top <= kBvhMaxDepth);
                stack[top++] = n.ref[c];
            }
        }
    }
    return est;
}

}  // namespace sdf
