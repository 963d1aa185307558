/// @file accurate_cross.h
/// @brief The normal (V1 - V0) x (V2 - V0) of a triangle to a few ulps of its own length,
/// however thin the triangle.
///
/// The plain cross product of the rounded edges is off by about u |E0| |E1|, i.e. by u / sin
/// theta relative to its length (theta the angle at V0): for a sliver with an angle of 1e-8
/// degrees the normal's direction would be off by 1e-6. Here the edges are exact (hi + lo,
/// Knuth's TwoSum), each component's a b - c d of their high parts by Kahan's algorithm with
/// FMA (within 2 ulps: Jeannerod, Louvet & Muller, Math. Comp. 82, 2013), and only the small
/// lo terms rounded plainly: within about 2u of the exact cross product of the vertices,
/// plus u^2 |E0| |E1|. Only IEEE
/// operations and fma, so host and device give the same bits (pack_triangle() runs on both).
#pragma once

#include <cmath>

#include "kernels/core/vec3.h"

namespace sdf {

template <typename T>
SDF_CPU_GPU SDF_INLINE T fused_multiply_add(T a, T b, T c) {
#if SDF_IS_GPU_CODE
    return fma(a, b, c);
#else
    return std::fma(a, b, c);
#endif
}

/// a - b = hi + lo exactly (Knuth's TwoSum of a and -b).
template <typename T>
SDF_CPU_GPU SDF_INLINE void exact_difference(T a, T b, T& hi, T& lo) {
    hi = a - b;
    const T bb = hi - a;
    lo = (a - (hi - bb)) - (b + bb);
}

/// a b - c d to about 1.5 ulps (Kahan's algorithm).
template <typename T>
SDF_CPU_GPU SDF_INLINE T difference_of_products(T a, T b, T c, T d) {
    const T w = c * d;
    const T e = fused_multiply_add(-c, d, w);
    const T f = fused_multiply_add(a, b, -w);
    return f + e;
}

/// (v1 - v0) x (v2 - v0), accurate however thin the triangle (see the file comment).
template <typename T>
SDF_CPU_GPU Vec3<T> accurate_triangle_cross(const Vec3<T>& v0, const Vec3<T>& v1, const Vec3<T>& v2) {
    Vec3<T> ah, al, bh, bl;
    exact_difference(v1.x, v0.x, ah.x, al.x);
    exact_difference(v1.y, v0.y, ah.y, al.y);
    exact_difference(v1.z, v0.z, ah.z, al.z);
    exact_difference(v2.x, v0.x, bh.x, bl.x);
    exact_difference(v2.y, v0.y, bh.y, bl.y);
    exact_difference(v2.z, v0.z, bh.z, bl.z);
    // (ah + al) x (bh + bl) = ah x bh + (ah x bl + al x bh) + al x bl; the last is below u^2.
    const Vec3<T> small = cross(ah, bl) + cross(al, bh);
    return {difference_of_products(ah.y, bh.z, ah.z, bh.y) + small.x,
            difference_of_products(ah.z, bh.x, ah.x, bh.z) + small.y,
            difference_of_products(ah.x, bh.y, ah.y, bh.x) + small.z};
}

}  // namespace sdf
