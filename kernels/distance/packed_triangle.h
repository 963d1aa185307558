/// @file packed_triangle.h
/// @brief Per-triangle constants and a branch-free squared distance for the hot loops of the
/// brute-force samplers (CPU vector loop, tuned CUDA kernel).
///
/// It minimises the same quadratic Q(s,t) as Eberly's algorithm (thesis section 3.2), but
/// with the 7 regions folded into "inside the triangle, or on one of its 3 clamped edges":
///   Q = inside ? (n . (B - P))^2 : min(Q_edge01, Q_edge20, Q_edge12),
/// where each edge minimum is a clamped 1-D quadratic and "inside" tests Eberly's
/// unconstrained minimiser (s, t) (region 0). Every branch becomes a select, so the loop
/// vectorises on the CPU and does not diverge on the GPU: 42 instructions a pair on sm_90.
/// Only the minimum search uses this form; the winning triangle is re-evaluated with
/// closest_point_on_triangle() in double for the closest point, feature and exact distance.
///
/// Precision. In float the edge terms expand |B - P|^2, so Q carries a rounding error of
/// about 1e-7 |B - P|^2, not 1e-7 Q: two triangles closer than that may be ranked either way.
/// The certified search (search_certificate.h) bounds this error rigorously and re-ranks the
/// triangles within it in double, so float searches return the double search's triangle. Slivers
/// (smallest angle below ~0.6 degrees, sin^2 < kSliverSin2) are searched by their edges only,
/// because (s, t) loses all accuracy there; their interior lies within the inradius of an
/// edge, so Q over-estimates by at most the squared inradius.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "kernels/core/vec3.h"

namespace sdf {

/// Triangles with sin^2 of an angle below this are searched by their edges only.
constexpr double kSliverSin2 = 1e-4;
/// The float search also searches triangles with sin^2 of an angle below this by their edges
/// only: its (s, t) are off by about 2^-24 |B - P| / sin^2, and a wrong inside/outside choice
/// costs the square of that, far more than the rest of the rounding for angles below ~6
/// degrees. Edges only over-estimates by at most the squared inradius instead, which the
/// certified search's bound counts (search_certificate.h). Double keeps kSliverSin2.
constexpr double kFloatSliverSin2 = 1e-2;

/// 24 scalars (96 bytes in float): six 16-byte loads on the GPU.
template <typename T>
struct alignas(16) PackedTriangle {
    T bx, by, bz;        ///< B = V0
    T e0x, e0y, e0z;     ///< 2 E0 = 2 (V1 - V0)
    T e1x, e1y, e1z;     ///< 2 E1 = 2 (V2 - V0)
    T nx, ny, nz;        ///< unit normal
    T sa, sb, ta, tb;    ///< s = sa 2d + sb 2e, t = ta 2d + tb 2e (Eberly's region-0 minimiser); sb..tb NaN =
                         ///< never inside, and then sa = the over-estimate bound (sliver_excess)
    T a, c;              ///< E0.E0, E1.E1
    T k01, k20;          ///< -1 / (2a), -1 / (2c): edge parameters from 2d and 2e
    T k12, m12;          ///< 1 / (2g), (c - b) / g with g = a - 2b + c, b = E0.E1: edge V2 -> V1
    T g, w12;            ///< g and 2 (b - c)
};

/// The next T above x (host and device).
template <typename T>
SDF_CPU_GPU SDF_INLINE T next_above(T x) {
#if SDF_IS_GPU_CODE
    if constexpr (std::is_same_v<T, float>) return nextafterf(x, INFINITY);
    else return nextafter(x, double(INFINITY));
#else
    return std::nextafter(x, T(INFINITY));
#endif
}

/// The constants of triangle (v0, v1, v2). Host and device compute them bit for bit alike
/// (IEEE operations only, no contraction: the build flags), so the GPU BVH build packs its
/// triangles where it sorts them instead of uploading the host's.
template <typename T>
SDF_CPU_GPU PackedTriangle<T> pack_triangle(const Vec3d& v0, const Vec3d& v1, const Vec3d& v2) {
    // Constants are formed in double and rounded once, so float and double runs agree.
    const Vec3d e0 = v1 - v0, e1 = v2 - v0;
    const double a = dot(e0, e0), b = dot(e0, e1), c = dot(e1, e1);
    const double g = a - 2.0 * b + c;
    const double det = a * c - b * b;
    const Vec3d n = normalize_or_zero(cross(e0, e1));
    // sin^2 of the angle at V0 is det / (a c); the smallest angle matters, and with the
    // edge lengths it is at most that one's, so test all three corners. (The first smallest,
    // as std::min({...}): a NaN first stays.)
    double sin2 = det / (a * c);
    if (det / (a * g) < sin2) sin2 = det / (a * g);
    if (det / (c * g) < sin2) sin2 = det / (c * g);
    const double sliver = sizeof(T) < sizeof(double) ? kFloatSliverSin2 : kSliverSin2;
    const bool interior = det > 0.0 && a > 0.0 && c > 0.0 && g > 0.0 && sin2 >= sliver;
    const T nan = std::numeric_limits<T>::quiet_NaN();  // NaN >= 0 is false: never inside
    // A triangle only float searches by its edges over-estimates there by at most its squared
    // inradius (2 area / perimeter)^2: kept in sa, which s = sa 2d + NaN 2e no longer needs.
    const bool float_only_sliver =
        sizeof(T) < sizeof(double) && det > 0.0 && a > 0.0 && c > 0.0 && g > 0.0 && sin2 >= kSliverSin2 && !interior;
    const double inradius = float_only_sliver ? std::sqrt(det) / (std::sqrt(a) + std::sqrt(c) + std::sqrt(g)) : 0.0;
    const T excess = next_above(T(inradius * inradius * 1.001));
    PackedTriangle<T> t{};
    t.bx = T(v0.x); t.by = T(v0.y); t.bz = T(v0.z);
    t.e0x = T(2 * e0.x); t.e0y = T(2 * e0.y); t.e0z = T(2 * e0.z);
    t.e1x = T(2 * e1.x); t.e1y = T(2 * e1.y); t.e1z = T(2 * e1.z);
    t.nx = T(n.x); t.ny = T(n.y); t.nz = T(n.z);
    // s = (b e - c d) / det, t = (b d - a e) / det with d = 2d / 2, e = 2e / 2.
    t.sa = interior ? T(-c / (2 * det)) : (sizeof(T) < sizeof(double) ? (float_only_sliver ? excess : T(0)) : nan);
    t.sb = interior ? T(b / (2 * det)) : nan;
    t.ta = interior ? T(b / (2 * det)) : nan;
    t.tb = interior ? T(-a / (2 * det)) : nan;
    t.a = T(a); t.c = T(c);
    t.k01 = T(a > 0 ? -1.0 / (2 * a) : 0.0);
    t.k20 = T(c > 0 ? -1.0 / (2 * c) : 0.0);
    t.k12 = T(g > 0 ? 1.0 / (2 * g) : 0.0);
    t.m12 = T(g > 0 ? (c - b) / g : 0.0);
    t.g = T(g);
    t.w12 = T(2 * (b - c));
    return t;
}

/// How much squared_distance() may over-estimate the double search's Q of this triangle
/// because float searches it by its edges only (kFloatSliverSin2): the certified search
/// (search_certificate.h) ranks candidates by Q - sliver_excess. 0 for every other triangle.
template <typename T>
SDF_CPU_GPU SDF_INLINE T sliver_excess(const PackedTriangle<T>& tri) {
    return tri.sb != tri.sb ? tri.sa : T(0);  // sb NaN: never inside; sa holds the bound
}

template <typename T>
SDF_CPU_GPU SDF_INLINE T saturate(T x) {
#if SDF_IS_GPU_CODE
    if constexpr (std::is_same_v<T, float>) return __saturatef(x);
#endif
    return x < T(0) ? T(0) : (x > T(1) ? T(1) : x);
}

/// Minimum; one FMNMX on the GPU (a plain a < b ? a : b costs a compare and a select there,
/// while on the CPU it is exactly what vminps computes).
template <typename T>
SDF_CPU_GPU SDF_INLINE T min_of(T a, T b) {
#if SDF_IS_GPU_CODE
    if constexpr (std::is_same_v<T, float>) return fminf(a, b);
#endif
    return a < b ? a : b;
}

/// Squared distance from p to the triangle, branch-free (see the file comment).
template <typename T>
SDF_CPU_GPU SDF_INLINE T squared_distance(const PackedTriangle<T>& tri, T px, T py, T pz) {
    const T dx = tri.bx - px, dy = tri.by - py, dz = tri.bz - pz;
    const T d2 = tri.e0x * dx + tri.e0y * dy + tri.e0z * dz;  // 2 E0.(B - P)
    const T e2 = tri.e1x * dx + tri.e1y * dy + tri.e1z * dz;  // 2 E1.(B - P)
    const T f = dx * dx + dy * dy + dz * dz;
    const T h = tri.nx * dx + tri.ny * dy + tri.nz * dz;

    // Region 0: Eberly's unconstrained minimiser (s, t) lies in the triangle.
    const T s = tri.sa * d2 + tri.sb * e2;
    const T t = tri.ta * d2 + tri.tb * e2;
    const bool inside = (s >= T(0)) & (t >= T(0)) & (s + t <= T(1));  // no branches

    // Edge V0 -> V1 (t = 0) and edge V0 -> V2 (s = 0).
    const T s01 = saturate(d2 * tri.k01);
    const T q01 = s01 * (tri.a * s01 + d2) + f;
    const T t20 = saturate(e2 * tri.k20);
    const T q20 = t20 * (tri.c * t20 + e2) + f;
    // Edge V2 -> V1 (s + t = 1), parametrised by s.
    const T de = d2 - e2;
    const T s12 = saturate(de * -tri.k12 + tri.m12);
    const T q12 = s12 * (tri.g * s12 + (de + tri.w12)) + ((f + tri.c) + e2);

    const T q_edges = min_of(min_of(q01, q20), q12);
    return inside ? h * h : q_edges;
}

template <typename T>
SDF_CPU_GPU SDF_INLINE T squared_distance(const PackedTriangle<T>& tri, const Vec3<T>& p) {
    return squared_distance(tri, p.x, p.y, p.z);
}

}  // namespace sdf
