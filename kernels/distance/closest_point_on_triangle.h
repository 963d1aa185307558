/// @file closest_point_on_triangle.h
/// @brief Exact point-triangle distance: D. Eberly, "Distance Between Point and Triangle in
/// 3D" (1999), as summarised in thesis section 3.2 and Figure 3-1.
///
/// The triangle is T(s,t) = B + s E0 + t E1 over D = {s >= 0, t >= 0, s + t <= 1}, and the
/// squared distance to P is the quadratic Q(s,t) = a s^2 + 2 b s t + c t^2 + 2 d s + 2 e t + f.
/// Its minimum over D lies in one of the 7 regions of the (s,t) plane: region 0 is the
/// triangle itself; regions 1, 3, 5 lie across one edge and regions 2, 4, 6 across a vertex.
/// The result names the feature that holds the closest point, which decides the sign.
#pragma once

#include "kernels/core/vec3.h"
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

/// Closest point on triangle (v0, v1, v2) to p, with Eberly's region classification.
/// Degenerate triangles (zero area) are handled by taking the nearest of the three edges.
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

    if (!(det > T(0)) || !(a > T(0)) || !(c > T(0))) {
        // Zero-area triangle: the closest point lies on one of its edges (or it is a point).
        s = T(0); t = T(0); feature = TriangleFeature::Vertex0;
        T best = length_squared(diff);
        TriangleFeature f;
        if (a > T(0)) {
            T s0 = clamp_on_edge01(a, d, f);
            T q = length_squared(diff + e0 * s0);
            if (q < best) { best = q; s = s0; t = T(0); feature = f; }
        }
        if (c > T(0)) {
            T t0 = clamp_on_edge20(c, e, f);
            T q = length_squared(diff + e1 * t0);
            if (q < best) { best = q; s = T(0); t = t0; feature = f; }
        }
        const T denom = a - T(2) * b + c;
        if (denom > T(0)) {
            T s0 = clamp_on_edge12((c + e) - (b + d), denom, f);
            T q = length_squared(diff + e0 * s0 + e1 * (T(1) - s0));
            if (q < best) { s = s0; t = T(1) - s0; feature = f; }
        }
    } else if (s + t <= det) {
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
