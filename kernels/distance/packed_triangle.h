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
/// triangles within it in double, so float searches return the double search's triangle.
///
/// Slivers (smallest angle below ~0.6 degrees in double, sin^2 < kSliverSin2; ~6 degrees in
/// float). Eberly's (s, t) = (sa 2d + sb 2e, ...) cancels there (|sa 2d| ~ |B - P| / sin^2),
/// so the branch-free form searches them by their edges only, which over-estimates Q by up to
/// the squared inradius (0.29 for a 100-long triangle of 0.5 degrees: a point on it ranked by
/// its edges). Double therefore evaluates them with sliver_squared_distance(): the vertex at
/// the largest angle becomes V0 (so the edge V1 V2 is the longest and its quadratic does not
/// cancel), the normal is accurate (accurate_cross.h), and "inside" is three edge functions
/// (n x E) . (P - B), each off by a few ulps of |B - P| E, whatever the angles. A point
/// misjudged inside lies within ~16 u |B - P| of two edge lines, so within that over the sine
/// of their angle of the triangle: Q is off by at most (16 u M)^2 / sin^2, which is below
/// 2^-45 M^2 down to kRobustSliverSin2; thinner slivers are searched by their edges (their
/// squared inradius is below kRobustSliverSin2 M^2). Float keeps its edges-only search of
/// slivers, with the squared inradius in sliver_excess(): the certified search re-ranks them
/// in double.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "kernels/core/vec3.h"
#include "kernels/distance/accurate_cross.h"

namespace sdf {

/// Triangles with sin^2 of an angle below this are slivers: double evaluates them with
/// sliver_squared_distance(), not the branch-free form.
constexpr double kSliverSin2 = 1e-4;
/// Double slivers thinner than this (sin^2 of the smallest angle) are searched by their edges
/// only (see the file comment): about 3.4e-6 degrees.
constexpr double kRobustSliverSin2 = 0x1p-47;
/// The float search searches triangles with sin^2 of an angle below this by their edges
/// only: its (s, t) are off by about 2^-24 |B - P| / sin^2, and a wrong inside/outside choice
/// costs the square of that, far more than the rest of the rounding for angles below ~6
/// degrees. Edges only over-estimates by at most the squared inradius instead, which the
/// certified search's bound counts (sliver_excess, search_certificate.h).
constexpr double kFloatSliverSin2 = 1e-2;

/// 24 scalars (96 bytes in float): six 16-byte loads on the GPU.
template <typename T>
struct alignas(16) PackedTriangle {
    T bx, by, bz;        ///< B = V0
    T e0x, e0y, e0z;     ///< 2 E0 = 2 (V1 - V0)
    T e1x, e1y, e1z;     ///< 2 E1 = 2 (V2 - V0)
    T nx, ny, nz;        ///< unit normal
    T sa, sb, ta, tb;    ///< s = sa 2d + sb 2e, t = ta 2d + tb 2e (Eberly's region-0 minimiser); sb NaN: a
                         ///< sliver, never inside here, and then sa = the over-estimate bound in float
                         ///< (sliver_excess), ta = 2 |E0 x E1| in double (sliver_squared_distance; NaN:
                         ///< edges only)
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

namespace detail {

/// The edge constants shared by every triangle (a, c, k01, k20, k12, m12, g, w12) from the
/// edges' dot products, and B, 2 E0, 2 E1.
template <typename T>
SDF_CPU_GPU SDF_INLINE void pack_edges(PackedTriangle<T>& t, const Vec3d& v0, const Vec3d& e0, const Vec3d& e1,
                                       double a, double b, double c, double g) {
    t.bx = T(v0.x); t.by = T(v0.y); t.bz = T(v0.z);
    t.e0x = T(2 * e0.x); t.e0y = T(2 * e0.y); t.e0z = T(2 * e0.z);
    t.e1x = T(2 * e1.x); t.e1y = T(2 * e1.y); t.e1z = T(2 * e1.z);
    t.a = T(a); t.c = T(c);
    t.k01 = T(a > 0 ? -1.0 / (2 * a) : 0.0);
    t.k20 = T(c > 0 ? -1.0 / (2 * c) : 0.0);
    t.k12 = T(g > 0 ? 1.0 / (2 * g) : 0.0);
    t.m12 = T(g > 0 ? (c - b) / g : 0.0);
    t.g = T(g);
    t.w12 = T(2 * (b - c));
}

/// sin^2 of the smallest angle from the accurate |E0 x E1|^2 and the squared edge lengths.
SDF_CPU_GPU SDF_INLINE double smallest_sin2(double cross2, double a, double c, double g) {
    // The smallest angle lies between the two longest edges.
    const double hi = a > c ? a : c, lo = a > c ? c : a;
    const double longest = g > hi ? g : hi, middle = g > hi ? hi : (g > lo ? g : lo);
    return cross2 / (longest * middle);
}

/// A double sliver (see the file comment): rotated so that V0 holds the largest angle (the
/// orientation, hence the normal, is kept), accurate normal, ta = 2 |E0 x E1| when its
/// interior is searched (sliver_squared_distance), NaN when only its edges are.
SDF_CPU_GPU inline PackedTriangle<double> pack_double_sliver(const Vec3d& v0, const Vec3d& v1, const Vec3d& v2) {
    const double l01 = length_squared(v1 - v0), l20 = length_squared(v2 - v0), l12 = length_squared(v2 - v1);
    // The vertex opposite the longest edge first.
    const bool keep = l12 >= l01 && l12 >= l20;
    const Vec3d w0 = keep ? v0 : (l01 >= l20 ? v2 : v1);
    const Vec3d w1 = keep ? v1 : (l01 >= l20 ? v0 : v2);
    const Vec3d w2 = keep ? v2 : (l01 >= l20 ? v1 : v0);
    const Vec3d e0 = w1 - w0, e1 = w2 - w0;
    const double a = dot(e0, e0), b = dot(e0, e1), c = dot(e1, e1);
    const double g = a - 2.0 * b + c;
    const Vec3d cross = accurate_triangle_cross(w0, w1, w2);
    const double cross2 = length_squared(cross), area2 = std::sqrt(cross2);  // area2 = 2 * area
    const bool interior = area2 > 0.0 && area2 < double(INFINITY) &&
                          smallest_sin2(cross2, length_squared(e0), length_squared(e1), length_squared(w2 - w1)) >=
                              kRobustSliverSin2;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    PackedTriangle<double> t{};
    pack_edges(t, w0, e0, e1, a, b, c, g);
    const Vec3d n = area2 > 0.0 ? cross / area2 : Vec3d(0.0);
    t.nx = n.x; t.ny = n.y; t.nz = n.z;
    t.sa = 0.0;
    t.sb = nan;
    t.ta = interior ? 2.0 * area2 : nan;
    t.tb = nan;
    return t;
}

/// The squared inradius (2 area / perimeter)^2 of a triangle, rounded up: how much its edge
/// distance may exceed its distance.
template <typename T>
SDF_CPU_GPU SDF_INLINE T squared_inradius_above(double area2, double a, double c, double g) {
    const double inradius = area2 / (std::sqrt(a) + std::sqrt(c) + std::sqrt(g));
    return next_above(T(inradius * inradius * 1.001));
}

}  // namespace detail

/// The constants of triangle (v0, v1, v2). Host and device compute them bit for bit alike
/// (IEEE operations and fma only, no contraction: the build flags), so the GPU BVH build
/// packs its triangles where it sorts them instead of uploading the host's.
template <typename T>
SDF_CPU_GPU PackedTriangle<T> pack_triangle(const Vec3d& v0, const Vec3d& v1, const Vec3d& v2) {
    constexpr bool kFloat = sizeof(T) < sizeof(double);
    // Constants are formed in double and rounded once, so float and double runs agree.
    const Vec3d e0 = v1 - v0, e1 = v2 - v0;
    const double a = dot(e0, e0), b = dot(e0, e1), c = dot(e1, e1);
    const double g = a - 2.0 * b + c;
    const double det = a * c - b * b;
    // sin^2 of the angle at V0 is det / (a c); the smallest angle matters, and with the
    // edge lengths it is at most that one's, so test all three corners. (The first smallest,
    // as std::min({...}): a NaN first stays.)
    double sin2 = det / (a * c);
    if (det / (a * g) < sin2) sin2 = det / (a * g);
    if (det / (c * g) < sin2) sin2 = det / (c * g);
    const bool interior = det > 0.0 && a > 0.0 && c > 0.0 && g > 0.0 && sin2 >= (kFloat ? kFloatSliverSin2 : kSliverSin2);
    if constexpr (!kFloat) {
        if (!interior) return detail::pack_double_sliver(v0, v1, v2);
    }
    const T nan = std::numeric_limits<T>::quiet_NaN();  // NaN >= 0 is false: never inside
    PackedTriangle<T> t{};
    detail::pack_edges(t, v0, e0, e1, a, b, c, g);
    const Vec3d n = normalize_or_zero(cross(e0, e1));
    t.nx = T(n.x); t.ny = T(n.y); t.nz = T(n.z);
    if (interior) {
        // s = (b e - c d) / det, t = (b d - a e) / det with d = 2d / 2, e = 2e / 2.
        t.sa = T(-c / (2 * det));
        t.sb = T(b / (2 * det));
        t.ta = T(b / (2 * det));
        t.tb = T(-a / (2 * det));
        return t;
    }
    // A float sliver: searched by its edges, which over-estimate by at most its squared
    // inradius (2 area / perimeter)^2, kept in sa (sliver_excess). Where double searches the
    // interior through Eberly's (s, t) (sin^2 >= kSliverSin2) from det; thinner ones from
    // the accurate area (det cancels), as double's sliver_squared_distance() sees them.
    const bool double_interior = det > 0.0 && a > 0.0 && c > 0.0 && g > 0.0 && sin2 >= kSliverSin2;
    const double area2 = double_interior ? std::sqrt(det) : length(accurate_triangle_cross(v0, v1, v2));
    const double g_edge = double_interior ? g : length_squared(v2 - v1);
    t.sa = area2 > 0.0 && area2 < double(INFINITY) ? detail::squared_inradius_above<T>(area2, a, c, g_edge) : T(0);
    t.sb = t.ta = t.tb = nan;
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

namespace detail {

/// min(Q_edge01, Q_edge20, Q_edge12): each a clamped 1-D quadratic from 2 E0.(B - P) = d2,
/// 2 E1.(B - P) = e2 and |B - P|^2 = f.
template <typename T>
SDF_CPU_GPU SDF_INLINE T edges_squared_distance(const PackedTriangle<T>& tri, T d2, T e2, T f) {
    // Edge V0 -> V1 (t = 0) and edge V0 -> V2 (s = 0).
    const T s01 = saturate(d2 * tri.k01);
    const T q01 = s01 * (tri.a * s01 + d2) + f;
    const T t20 = saturate(e2 * tri.k20);
    const T q20 = t20 * (tri.c * t20 + e2) + f;
    // Edge V2 -> V1 (s + t = 1), parametrised by s.
    const T de = d2 - e2;
    const T s12 = saturate(de * -tri.k12 + tri.m12);
    const T q12 = s12 * (tri.g * s12 + (de + tri.w12)) + ((f + tri.c) + e2);
    return min_of(min_of(q01, q20), q12);
}

}  // namespace detail

/// Squared distance from p to the triangle, branch-free (see the file comment); a sliver
/// (sliver_excess) by its edges only.
template <typename T>
SDF_CPU_GPU SDF_INLINE T branch_free_squared_distance(const PackedTriangle<T>& tri, T px, T py, T pz) {
    const T dx = tri.bx - px, dy = tri.by - py, dz = tri.bz - pz;
    const T d2 = tri.e0x * dx + tri.e0y * dy + tri.e0z * dz;  // 2 E0.(B - P)
    const T e2 = tri.e1x * dx + tri.e1y * dy + tri.e1z * dz;  // 2 E1.(B - P)
    const T f = dx * dx + dy * dy + dz * dz;
    const T h = tri.nx * dx + tri.ny * dy + tri.nz * dz;

    // Region 0: Eberly's unconstrained minimiser (s, t) lies in the triangle.
    const T s = tri.sa * d2 + tri.sb * e2;
    const T t = tri.ta * d2 + tri.tb * e2;
    const bool inside = (s >= T(0)) & (t >= T(0)) & (s + t <= T(1));  // no branches

    const T q_edges = detail::edges_squared_distance(tri, d2, e2, f);
    return inside ? h * h : q_edges;
}

/// Whether double searches this sliver through its interior with sliver_squared_distance().
template <typename T>
SDF_CPU_GPU SDF_INLINE bool is_interior_sliver(const PackedTriangle<T>& tri) {
    return tri.sb != tri.sb && tri.ta == tri.ta;  // sb NaN: a sliver; ta not NaN: 2 |E0 x E1|
}

/// Squared distance from p to a double sliver (see the file comment): inside iff the three
/// edge functions w01 = (n x 2E0).(P - B), w20 = (2E1 x n).(P - B) and 2 |E0 x E1| - w01 - w20
/// are >= 0; otherwise the edges as in the branch-free form.
template <typename T>
SDF_CPU_GPU SDF_INLINE T sliver_squared_distance(const PackedTriangle<T>& tri, T px, T py, T pz) {
    const T dx = tri.bx - px, dy = tri.by - py, dz = tri.bz - pz;
    const T d2 = tri.e0x * dx + tri.e0y * dy + tri.e0z * dz;
    const T e2 = tri.e1x * dx + tri.e1y * dy + tri.e1z * dz;
    const T f = dx * dx + dy * dy + dz * dz;
    const T h = tri.nx * dx + tri.ny * dy + tri.nz * dz;
    const Vec3<T> n(tri.nx, tri.ny, tri.nz), delta(dx, dy, dz);
    const T w01 = -dot(cross(n, Vec3<T>(tri.e0x, tri.e0y, tri.e0z)), delta);
    const T w20 = dot(cross(n, Vec3<T>(tri.e1x, tri.e1y, tri.e1z)), delta);
    const bool inside = (w01 >= T(0)) & (w20 >= T(0)) & (w01 + w20 <= tri.ta);
    const T q_edges = detail::edges_squared_distance(tri, d2, e2, f);
    return inside ? h * h : q_edges;
}

/// Squared distance from p to the triangle: the one every search ranks by. Float: the
/// branch-free form. Double: the same, and sliver_squared_distance() for slivers. Loops that
/// vectorise over triangles run the branch-free form and then re-evaluate their slivers.
template <typename T>
SDF_CPU_GPU SDF_INLINE T squared_distance(const PackedTriangle<T>& tri, T px, T py, T pz) {
    if constexpr (sizeof(T) == sizeof(double)) {
        if (is_interior_sliver(tri)) return sliver_squared_distance(tri, px, py, pz);
    }
    return branch_free_squared_distance(tri, px, py, pz);
}

template <typename T>
SDF_CPU_GPU SDF_INLINE T squared_distance(const PackedTriangle<T>& tri, const Vec3<T>& p) {
    return squared_distance(tri, p.x, p.y, p.z);
}

}  // namespace sdf
