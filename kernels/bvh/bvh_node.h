/// @file bvh_node.h
/// @brief The flat, GPU-friendly node of the triangle BVH: a binary node that stores the
/// boxes of both children (Aila & Laine, "Understanding the Efficiency of Ray Traversal on
/// GPUs", HPG 2009), so one 64-byte load lets a query test both children at once.
///
/// Node 0 is the root. A child is either another node (count == 0, ref = node index) or a
/// leaf (count > 0, ref = first triangle of the leaf's contiguous range in BVH order). A
/// leaf with count == 0 and an inverted box (min = +inf, max = -inf) is the empty child of
/// a root whose whole mesh fits one leaf. Boxes are float, rounded outward from the
/// double-precision triangle bounds, so they contain every triangle exactly and serve the
/// float and the double search alike.
#pragma once

#include <cstdint>

#include "kernels/core/host_device.h"

namespace sdf {

struct alignas(64) BvhNode {
    float min_x[2], max_x[2];  ///< child boxes, axis by axis: [0] left child, [1] right child
    float min_y[2], max_y[2];
    float min_z[2], max_z[2];
    int32_t ref[2];    ///< node index (count == 0) or first triangle in BVH order (leaf)
    int32_t count[2];  ///< triangles in the leaf; 0 for an inner node
};
static_assert(sizeof(BvhNode) == 64, "BvhNode must stay one 64-byte line");

SDF_CPU_GPU constexpr bool bvh_child_is_leaf(int32_t ref, int32_t count) { return count > 0 || ref < 0; }
SDF_CPU_GPU constexpr bool bvh_child_is_leaf(const BvhNode& n, int c) { return bvh_child_is_leaf(n.ref[c], n.count[c]); }

/// Deepest node level a builder may produce; the traversal stack holds one entry per level.
constexpr int kBvhMaxDepth = 64;

}  // namespace sdf
