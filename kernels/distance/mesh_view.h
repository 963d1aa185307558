/// @file mesh_view.h
/// @brief Plain pointers to a prepared mesh's arrays, as kernels see them (host or device).
///
/// Owned by cpu_reference::PreparedMesh (host) or by a CUDA upload; kernels only read it.
#pragma once

#include "kernels/core/vec3.h"
#include "kernels/distance/packed_triangle.h"

namespace sdf {

/// The largest finite value of T (numeric_limits is not usable in device code).
template <typename T>
inline constexpr T kLargest = sizeof(T) == 4 ? T(3.40282346638528859811704183484516925e+38) : T(1.79769313486231570814527423731704357e+308);

template <typename T>
struct MeshView {
    const Vec3<T>* vertices = nullptr;
    const Int3* triangles = nullptr;          ///< vertex ids, counter-clockwise from outside
    const Vec3<T>* face_normals = nullptr;    ///< one per triangle (unit)
    const Vec3<T>* edge_normals = nullptr;    ///< 3 per triangle: edge e = (v_e, v_(e+1)%3)
    const Vec3<T>* vertex_normals = nullptr;  ///< one per vertex, angle-weighted
    const PackedTriangle<T>* packed = nullptr;  ///< hot-loop constants, one per triangle
    int num_triangles = 0;
    int num_vertices = 0;
    /// The vertices' bounding box. A point strictly outside it is outside every closed
    /// surface (its winding number is 0), so signed_sample() gives it the outside sign
    /// whatever the pseudonormal of the chosen feature says: far from the mesh the search
    /// cannot always separate the nearest triangle from one on the far side, whose
    /// pseudonormal points away. The default (the whole space) disables the rule.
    Vec3<T> box_lo{-kLargest<T>, -kLargest<T>, -kLargest<T>};
    Vec3<T> box_hi{kLargest<T>, kLargest<T>, kLargest<T>};

    SDF_CPU_GPU bool outside_box(const Vec3<T>& p) const {
        return p.x < box_lo.x || p.y < box_lo.y || p.z < box_lo.z || p.x > box_hi.x || p.y > box_hi.y || p.z > box_hi.z;
    }
};

}  // namespace sdf
