/// @file closest_point_on_triangle.h
/// @brief Exact point-triangle distance: D. Eberly, "Distance Between Point and Triangle in
/// 3D" (1999), as summarised in thesis section 3.2 and Figure 3-1.
///
/// The triangle is T(s,t) = B + s E0 + t E1 over D = {s >= 0, t >= 0, s + t <= 1}, and the
/// squared distance to P is the quadratic Q(s,t) = a s^2 + 2 b s t + c t^2 + 2 d s + 2 e t + f.
/// Its minimum over D lies in one of the 7 regions of the (s,t) plane: region 0 is the
/// triangle itself; regions 1, 3, 5 lie across one edge and regions 2, 4, 6 across a vertex.
/// The result names the feature that holds the closest point, which decides the sign.
///
/// Slivers. (s, t) solve a 2 x 2 system whose condition is 1 / sin^2 of the angle at V0, so
/// where that angle's sin^2 is below kSliverSin2 (or the triangle has no area) the closest
/// point is found as for the search's slivers (packed_triangle.h): inside iff three edge
/// functions with an accurate normal say so, else the nearest of the three edges, each from
/// its own end points (closest_point_on_sliver()).
#pragma once

#include <limits>

#include "kernels/core/vec3.h"
#include "kernels/distance/accurate_cross.h"
#include "kernels/distance/packed_triangle.h"
#include "kernels/distance/triangle_feature.h"

namespace sdf {

template <typename T>
struct TriangleClosestPoint {
    Vec3<T> point;            ///< closest point on the triangle
    T s{}, t{};               ///< its parameters: point = V0 + s (V1 - V0) + t (V2 - V0)
    T distance_squared{};     ///< |P - point|^2, computed from the difference vector
    TriangleFeature feature{TriangleFeature::Face};
};

namespace detail {

/// Minimises Q along the edge t = 0 (V0 -> V1): returns s in [0, 1] and sets the feature.
template <typename T>
SDF_CPU_GPU SDF_INLINE T clamp_on_edge01(T a, T d, TriangleFeature& feature) {
    if (d >= T(0)) { feature = TriangleFeature::Vertex0; return T(0); }
    if (-d >= a) { feature = TriangleFeature::Vertex1; return T(1); }
    feature = TriangleFeature::Edge01;
    return -d / a;
}

/// Minimises Q along the edge s = 0 (V0 -> V2): returns t in [0, 1] and sets the feature.
template <typename T>
SDF_CPU_GPU SDF_INLINE T clamp_on_edge20(T c, T e, TriangleFeature& feature) {
    if (e >= T(0)) { feature = TriangleFeature::Vertex0; return T(0); }
    if (-e >= c) { feature = TriangleFeature::Vertex2; return T(1); }
    feature = TriangleFeature::Edge20;
    return -e / c;
}

/// Minimises Q along the edge s + t = 1 (V2 -> V1) given numer = (c + e) - (b + d) and
/// denom = a - 2b + c: returns s in [0, 1] (t = 1 - s) and sets the feature.
template <typename T>
SDF_CPU_GPU SDF_INLINE T clamp_on_edge12(T numer, T denom, TriangleFeature& feature) {
    if (numer <= T(0)) { feature = TriangleFeature::Vertex2; return T(0); }
    if (numer >= denom) { feature = TriangleFeature::Vertex1; return T(1); }
    feature = TriangleFeature::Edge12;
    return numer / denom;
}

}  // namespace detail

/// T(s,t) = V0 + s E0 + t E1; vertex features return the vertex itself, so a closest point
/// at a vertex is exactly on the mesh. Shared by Eberly's algorithm and the thesis kernel's
/// "sign and gradient after" step, which rebuilds the point from the stored (s, t).
template <typename T>
SDF_CPU_GPU SDF_INLINE Vec3<T> point_on_triangle(const Vec3<T>& v0, const Vec3<T>& v1, const Vec3<T>& v2, T s, T t,
                                                 TriangleFeature feature) {
    switch (feature) {
        case TriangleFeature::Vertex0: return v0;
        case TriangleFeature::Vertex1: return v1;
        case TriangleFeature::Vertex2: return v2;
        default: return v0 + (v1 - v0) * s + (v2 - v0) * t;
    }
}

/// Closest point on a sliver (see the file comment), in the parameters of (v0, v1, v2).
template <typename T>
SDF_CPU_GPU TriangleClosestPoint<T> closest_point_on_sliver(const Vec3<T>& p, const Vec3<T>& v0, const Vec3<T>& v1,
                                                            const Vec3<T>& v2) {
    using detail::clamp_on_edge01;
    using detail::clamp_on_edge12;
    using detail::clamp_on_edge20;
    const Vec3<T> e0 = v1 - v0, e1 = v2 - v0, e12 = v1 - v2, diff = v0 - p, diff2 = v2 - p;
    const T a = dot(e0, e0), c = dot(e1, e1), g = dot(e12, e12);
    T s = T(0), t = T(0);
    TriangleFeature feature = TriangleFeature::Vertex0;
    // The interior: inside iff the three edge functions (n x (V_k+1 - V_k)) . (P - V) are
    // >= 0, n the accurate unit normal and V the edge's end nearer to P, so that each is off
    // by a few ulps of |P - V| |E|: a point beyond a sharp vertex (where a misjudged point
    // would be far from the triangle) is judged relative to that vertex.
    const Vec3<T> cr = accurate_triangle_cross(v0, v1, v2);
    const T cross2 = length_squared(cr), area2 = std::sqrt(cross2);
    // sin^2 of the smallest angle (between the two longest edges) at least (64 u)^2: below,
    // the inradius is below 64 u times the longest edge and the edges alone are as exact.
    const T hi = a > c ? a : c, lo = a > c ? c : a;
    const T longest = g > hi ? g : hi, middle = g > hi ? hi : (g > lo ? g : lo);
    const T robust = T(64) * std::numeric_limits<T>::epsilon();
    if (area2 > T(0) && cross2 >= robust * robust * (longest * middle)) {
        const Vec3<T> n = cr / area2;
        const Vec3<T> corner[3] = {v0, v1, v2};
        T w[3];  // w[k]: area2 x the barycentric of the corner opposite edge k -> k + 1
        for (int k = 0; k < 3; ++k) {
            const Vec3<T>& from = corner[k];
            const Vec3<T>& to = corner[k == 2 ? 0 : k + 1];
            const Vec3<T> nearer = length_squared(p - from) <= length_squared(p - to) ? from : to;
            w[k] = dot(cross(n, to - from), p - nearer);
        }
        if (w[0] >= T(0) && w[1] >= T(0) && w[2] >= T(0)) {
            // The point is P's projection, not sum lambda V: a barycentric is an edge function
            // over a height, which on a sliver may be tiny, so lambda's error times a long edge
            // would move the point far along the sliver.
            TriangleClosestPoint<T> r;
            r.s = w[2] / area2;  // the barycentric of v1 (opposite edge v2 -> v0)
            r.t = w[0] / area2;  // of v2
            r.feature = TriangleFeature::Face;
            r.point = p - n * dot(n, p - v0);
            r.distance_squared = length_squared(p - r.point);
            return r;
        }
    }
    // The nearest of the three edges (V0 if none has length).
    T best = length_squared(diff);
    TriangleFeature f;
    if (a > T(0)) {
        const T s0 = clamp_on_edge01(a, dot(e0, diff), f);
        const T q = length_squared(diff + e0 * s0);
        if (q < best) { best = q; s = s0; t = T(0); feature = f; }
    }
    if (c > T(0)) {
        const T t0 = clamp_on_edge20(c, dot(e1, diff), f);
        const T q = length_squared(diff + e1 * t0);
        if (q < best) { best = q; s = T(0); t = t0; feature = f; }
    }
    if (g > T(0)) {  // V2 + s (V1 - V2)
        const T s0 = clamp_on_edge12(-dot(e12, diff2), g, f);
        const T q = length_squared(diff2 + e12 * s0);
        if (q < best) { s = s0; t = T(1) - s0; feature = f; }
    }
    TriangleClosestPoint<T> r;
    r.s = s;
    r.t = t;
    r.feature = feature;
    r.point = point_on_triangle(v0, v1, v2, s, t, feature);
    r.distance_squared = length_squared(p - r.point);
    return r;
}

/// Closest point on triangle (v0, v1, v2) to p, with Eberly's region classification;
/// slivers and zero-area triangles by closest_point_on_sliver().
template <typename T>
SDF_CPU_GPU TriangleClosestPoint<T> closest_point_on_triangle(const Vec3<T>& p, const Vec3<T>& v0,
                                                              const Vec3<T>& v1, const Vec3<T>& v2) {
    using detail::clamp_on_edge01;
    using detail::clamp_on_edge12;
    using detail::clamp_on_edge20;

    const Vec3<T> e0 = v1 - v0, e1 = v2 - v0, diff = v0 - p;
    const T a = dot(e0, e0), b = dot(e0, e1), c = dot(e1, e1);
    const T d = dot(e0, diff), e = dot(e1, diff);
    const T det = a * c - b * b;
    T s = b * e - c * d;
    T t = b * d - a * e;
    TriangleFeature feature = TriangleFeature::Face;

    if (!(det >= T(kSliverSin2) * a * c) || !(a > T(0)) || !(c > T(0)))
        return closest_point_on_sliver(p, v0, v1, v2);  // also zero-area triangles
    if (s + t <= det) {
        if (s < T(0)) {
            if (t < T(0)) {  // region 4: the minimum lies on edge t = 0 or edge s = 0
                if (d < T(0)) {
                    t = T(0);
                    s = clamp_on_edge01(a, d, feature);
                } else {
                    s = T(0);
                    t = clamp_on_edge20(c, e, feature);
                }
            } else {  // region 3: edge s = 0
                s = T(0);
                t = clamp_on_edge20(c, e, feature);
            }
        } else if (t < T(0)) {  // region 5: edge t = 0
            t = T(0);
            s = clamp_on_edge01(a, d, feature);
        } else {  // region 0: inside the triangle
            const T inv_det = T(1) / det;
            s *= inv_det;
            t *= inv_det;
            feature = TriangleFeature::Face;
        }
    } else {
        if (s < T(0)) {  // region 2: edge s + t = 1 or edge s = 0
            const T tmp0 = b + d, tmp1 = c + e;
            if (tmp1 > tmp0) {
                s = clamp_on_edge12(tmp1 - tmp0, a - T(2) * b + c, feature);
                t = T(1) - s;
            } else {
                s = T(0);
                t = clamp_on_edge20(c, e, feature);
            }
        } else if (t < T(0)) {  // region 6: edge s + t = 1 or edge t = 0
            const T tmp0 = b + e, tmp1 = a + d;
            if (tmp1 > tmp0) {
                // Parametrised by t along V1 -> V2; clamp_on_edge12 returns the s of that edge.
                T tt = clamp_on_edge12(tmp1 - tmp0, a - T(2) * b + c, feature);
                // clamp_on_edge12 labels tt = 1 as Vertex1 and tt = 0 as Vertex2; swap for t.
                if (feature == TriangleFeature::Vertex1) feature = TriangleFeature::Vertex2;
                else if (feature == TriangleFeature::Vertex2) feature = TriangleFeature::Vertex1;
                t = tt;
                s = T(1) - t;
            } else {
                t = T(0);
                s = clamp_on_edge01(a, d, feature);
            }
        } else {  // region 1: edge s + t = 1
            s = clamp_on_edge12((c + e) - (b + d), a - T(2) * b + c, feature);
            t = T(1) - s;
        }
    }

    TriangleClosestPoint<T> r;
    r.s = s;
    r.t = t;
    r.feature = feature;
    r.point = point_on_triangle(v0, v1, v2, s, t, feature);
    r.distance_squared = length_squared(p - r.point);
    return r;
}

}  // namespace sdf
