/// @file bvh_view.h
/// @brief Plain pointers to a built BVH, as queries see it on the host or the device.
///
/// Owned by cpu_reference/bvh (host) or by the CUDA upload; queries only read it. The
/// packed triangles are stored in BVH order (each leaf a contiguous range), and
/// `triangle_index` maps a BVH slot back to the prepared mesh's triangle index.
#pragma once

#include "kernels/bvh/bvh_node.h"
#include "kernels/distance/packed_triangle.h"
#include "kernels/distance/search_certificate.h"

namespace sdf {

template <typename T>
struct BvhView {
    const BvhNode* nodes = nullptr;
    const PackedTriangle<T>* packed = nullptr;  ///< search constants, in BVH order
    const int32_t* triangle_index = nullptr;    ///< BVH slot -> prepared-mesh triangle
    int num_nodes = 0;
    int num_triangles = 0;
    /// Added to every pruning radius (search_certificate.h): set on double views, so that the
    /// double search equals the double brute force whatever the tree; zero on float views.
    PruneMargin<T> margin{};

    /// This view's margin over other copies of the same arrays (a device upload).
    BvhView with_arrays(const BvhNode* n, const PackedTriangle<T>* p, const int32_t* index) const {
        BvhView v = *this;
        v.nodes = n;
        v.packed = p;
        v.triangle_index = index;
        return v;
    }
};

}  // namespace sdf
