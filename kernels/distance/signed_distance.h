/// @file signed_distance.h
/// @brief Signed distance, exact gradient and closest feature of a point, given the triangle
/// that holds its closest point.
///
/// Sign: Baerentzen & Aanaes, "Signed distance computation using the angle weighted
/// pseudonormal" (2005): with C the closest point and N the angle-weighted pseudonormal of
/// the feature (face, edge or vertex) that holds C, P is outside iff (P - C) . N >= 0; a point
/// outside the mesh's bounding box is outside whatever N says (MeshView::box_lo).
/// Negative inside (DESIGN.md). Gradient (thesis section 3.4): the unit vector from C to P
/// times the sign; at distance 0 it is the feature's pseudonormal.
#pragma once

#include "kernels/distance/closest_point_on_triangle.h"
#include "kernels/distance/mesh_view.h"

namespace sdf {

template <typename T>
struct SignedDistanceSample {
    T distance{};            ///< signed: negative inside
    Vec3<T> gradient{};      ///< unit length
    Vec3<T> closest_point{};
    int triangle{-1};        ///< index into the prepared mesh
    TriangleFeature feature{TriangleFeature::Face};
};

/// Angle-weighted pseudonormal of the feature of `triangle` that holds the closest point.
template <typename T>
SDF_CPU_GPU Vec3<T> feature_pseudonormal(const MeshView<T>& mesh, int triangle, TriangleFeature f) {
    if (f == TriangleFeature::Face) return mesh.face_normals[triangle];
    if (is_edge(f)) return mesh.edge_normals[3 * triangle + edge_index(f)];
    return mesh.vertex_normals[mesh.triangles[triangle][vertex_index(f)]];
}

/// Sign and gradient of p given its closest point on `triangle` and that point's feature.
template <typename T>
SDF_CPU_GPU SignedDistanceSample<T> signed_sample(const MeshView<T>& mesh, const Vec3<T>& p, int triangle,
                                                  const Vec3<T>& closest, TriangleFeature feature) {
    const Vec3<T> n = feature_pseudonormal(mesh, triangle, feature);
    const Vec3<T> away = p - closest;
    const T dist = std::sqrt(length_squared(away));
    const bool inside = !mesh.outside_box(p) && dot(away, n) < T(0);

    SignedDistanceSample<T> r;
    r.distance = inside ? -dist : dist;
    r.gradient = dist > T(0) ? away * ((inside ? T(-1) : T(1)) / dist) : n;
    r.closest_point = closest;
    r.triangle = triangle;
    r.feature = feature;
    return r;
}

/// Full evaluation of p against one triangle: Eberly's closest point, sign and gradient.
template <typename T>
SDF_CPU_GPU SignedDistanceSample<T> signed_distance_to_triangle(const MeshView<T>& mesh, const Vec3<T>& p,
                                                                int triangle) {
    const Int3 tri = mesh.triangles[triangle];
    const TriangleClosestPoint<T> cp =
        closest_point_on_triangle(p, mesh.vertices[tri.x], mesh.vertices[tri.y], mesh.vertices[tri.z]);
    return signed_sample(mesh, p, triangle, cp.point, cp.feature);
}

/// Reference brute force over all triangles with Eberly's algorithm per pair (the thesis's
/// per-pair computation). Ties keep the lowest triangle index.
template <typename T>
SDF_CPU_GPU int nearest_triangle_eberly(const MeshView<T>& mesh, const Vec3<T>& p) {
    int best = -1;
    T best_d2 = T(0);
    for (int i = 0; i < mesh.num_triangles; ++i) {
        const Int3 tri = mesh.triangles[i];
        const T d2 = closest_point_on_triangle(p, mesh.vertices[tri.x], mesh.vertices[tri.y],
                                               mesh.vertices[tri.z]).distance_squared;
        if (best < 0 || d2 < best_d2) { best = i; best_d2 = d2; }
    }
    return best;
}

}  // namespace sdf
