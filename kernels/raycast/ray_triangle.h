/// @file ray_triangle.h
/// @brief Watertight ray-triangle intersection: Woop, Benthin & Wald, "Watertight
/// Ray/Triangle Intersection", JCGT 2(1), 2013.
///
/// The ray is sheared so that it runs along +z from the origin; the triangle's vertices are
/// transformed the same way and the test becomes three 2-D edge functions U, V, W of the
/// origin. A hit needs all three >= 0 or all <= 0 (not all zero). Because a shared edge
/// gives exactly opposite edge-function values in its two triangles (the same products in
/// the same order), a ray through an edge or a vertex of a closed mesh hits at least one of
/// the triangles sharing it: no cracks, with no tolerance to choose. The reference renderer
/// runs it in double. Both faces count (no culling).
#pragma once

#include <cmath>

#include "kernels/raycast/camera.h"

namespace sdf {

/// The per-ray constants of the test (axis permutation and shear).
template <typename T>
struct WatertightRay {
    Vec3<T> origin{};
    int kx = 0, ky = 1, kz = 2;
    T sx{}, sy{}, sz{};
};

template <typename T>
SDF_CPU_GPU WatertightRay<T> make_watertight_ray(const Ray<T>& ray) {
    WatertightRay<T> w;
    w.origin = ray.origin;
    const Vec3<T>& d = ray.direction;
    const T ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    w.kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    w.kx = (w.kz + 1) % 3;
    w.ky = (w.kx + 1) % 3;
    if (d[w.kz] < T(0)) { const int t = w.kx; w.kx = w.ky; w.ky = t; }  // keep the winding
    w.sx = d[w.kx] / d[w.kz];
    w.sy = d[w.ky] / d[w.kz];
    w.sz = T(1) / d[w.kz];
    return w;
}

template <typename T>
struct TriangleHit {
    T t{};
    T b0{}, b1{}, b2{};  ///< barycentric weights of vertices a, b, c
};

/// Intersects triangle (a, b, c) with t in (0, t_max); writes the hit and returns true.
template <typename T>
SDF_CPU_GPU bool intersect_watertight(const WatertightRay<T>& r, const Vec3<T>& a, const Vec3<T>& b, const Vec3<T>& c,
                                      T t_max, TriangleHit<T>* hit) {
    // Vertices relative to the origin, sheared onto the ray's frame
    const Vec3<T> A = a - r.origin, B = b - r.origin, C = c - r.origin;
    const T ax = A[r.kx] - r.sx * A[r.kz], ay = A[r.ky] - r.sy * A[r.kz];
    const T bx = B[r.kx] - r.sx * B[r.kz], by = B[r.ky] - r.sy * B[r.kz];
    const T cx = C[r.kx] - r.sx * C[r.kz], cy = C[r.ky] - r.sy * C[r.kz];
    // Edge functions; a common sign (zeros allowed) means the ray passes inside
    const T u = cx * by - cy * bx;
    const T v = ax * cy - ay * cx;
    const T w = bx * ay - by * ax;
    if ((u < T(0) || v < T(0) || w < T(0)) && (u > T(0) || v > T(0) || w > T(0))) return false;
    const T det = u + v + w;
    if (det == T(0)) return false;
    // Scaled hit distance, compared without dividing
    const T az = r.sz * A[r.kz], bz = r.sz * B[r.kz], cz = r.sz * C[r.kz];
    const T t_scaled = u * az + v * bz + w * cz;
    if (det > T(0) ? (t_scaled <= T(0) || t_scaled >= t_max * det) : (t_scaled >= T(0) || t_scaled <= t_max * det))
        return false;
    const T inv = T(1) / det;
    hit->t = t_scaled * inv;
    hit->b0 = u * inv;
    hit->b1 = v * inv;
    hit->b2 = w * inv;
    return true;
}

}  // namespace sdf
