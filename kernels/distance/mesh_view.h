/// @file mesh_view.h
/// @brief Plain pointers to a prepared mesh's arrays, as kernels see them (host or device).
///
/// Owned by cpu_reference::PreparedMesh (host) or by a CUDA upload; kernels only read it.
#pragma once

#include "kernels/core/vec3.h"
#include "kernels/distance/packed_triangle.h"

namespace sdf {

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
};

}  // namespace sdf
