/// @file bvh_view.h
/// @brief Plain pointers to a built BVH, as queries see it on the host or the device.
///
/// Owned by cpu_reference/bvh (host) or by the CUDA upload; queries only read it. The
/// packed triangles are stored in BVH order (each leaf a contiguous range), and
/// `triangle_index` maps a BVH slot back to the prepared mesh's triangle index.
#pragma once

#include "kernels/bvh/bvh_node.h"
#include "kernels/distance/packed_triangle.h"

namespace sdf {

template <typename T>
struct BvhView {
    const BvhNode* nodes = nullptr;
    const PackedTriangle<T>* packed = nullptr;  ///< search constants, in BVH order
    const int32_t* triangle_index = nullptr;    ///< BVH slot -> prepared-mesh triangle
    int num_nodes = 0;
    int num_triangles = 0;
};

}  // namespace sdf
