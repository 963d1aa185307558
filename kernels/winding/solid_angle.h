/// @file solid_angle.h
/// @brief The signed solid angle of a triangle seen from a point, and the exact generalized
/// winding number of a mesh as the sum of them, written once for host and device.
///
/// Van Oosterom & Strackee, "The Solid Angle of a Plane Triangle" (IEEE TBME 1983): with
/// a, b, c the corners relative to p,
///   tan(Omega / 2) = a . (b x c) / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|),
/// evaluated with atan2 so that Omega covers (-2 pi, 2 pi]. Positive when p sees the
/// triangle's back, i.e. when p is behind its counter-clockwise normal, the inside of an
/// outward-oriented mesh. The generalized winding number (Jacobson, Kavan & Sorkine-Hornung,
/// "Robust Inside-Outside Segmentation using Generalized Winding Numbers", SIGGRAPH 2013,
/// eq. 5) is w(p) = sum Omega_i / (4 pi): 1 inside and 0 outside a closed, outward-oriented
/// mesh, k inside k overlapping closed parts, and a smooth in-between value near holes.
#pragma once

#include <cmath>

#include "kernels/core/vec3.h"
#include "kernels/distance/mesh_view.h"

namespace sdf {

template <typename T>
SDF_CPU_GPU constexpr T inverse_four_pi() { return T(0.079577471545947667884441881686257181); }

/// Signed solid angle of triangle (v0, v1, v2) seen from p, in (-2 pi, 2 pi]. 0 for p in the
/// triangle's plane outside it (and for p on the triangle, where it is undefined).
/// The numerator and denominator of Van Oosterom & Strackee's tan(Omega / 2) (above): the
/// one formula of triangle_solid_angle() and of the CPU's packet evaluation.
template <typename T>
SDF_CPU_GPU SDF_INLINE void solid_angle_terms(const Vec3<T>& p, const Vec3<T>& v0, const Vec3<T>& v1, const Vec3<T>& v2,
                                              T& numerator, T& denominator) {
    const Vec3<T> a = v0 - p, b = v1 - p, c = v2 - p;
    const T la = length(a), lb = length(b), lc = length(c);
    numerator = dot(a, cross(b, c));
    denominator = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
}

template <typename T>
SDF_CPU_GPU SDF_INLINE T triangle_solid_angle(const Vec3<T>& p, const Vec3<T>& v0, const Vec3<T>& v1, const Vec3<T>& v2) {
    T numerator, denominator;
    solid_angle_terms(p, v0, v1, v2, numerator, denominator);
    return T(2) * std::atan2(numerator, denominator);
}

/// Exact generalized winding number: the sum over every triangle (O(triangles) per point;
/// the reference for the fast evaluation of fast_winding_number.h).
template <typename T>
SDF_CPU_GPU T winding_number_exact(const MeshView<T>& mesh, const Vec3<T>& p) {
    T sum = T(0);
    for (int i = 0; i < mesh.num_triangles; ++i) {
        const Int3 t = mesh.triangles[i];
        sum += triangle_solid_angle(p, mesh.vertices[t.x], mesh.vertices[t.y], mesh.vertices[t.z]);
    }
    return sum * inverse_four_pi<T>();
}

}  // namespace sdf
