/// @file box_query.h
/// @brief The leaves of a BVH whose boxes meet a box: a query of the one nearest-first walk
/// (traversal.h) without keys, every child whose box meets the box entered in child order.
/// The CPU's band sweep gathers a block's triangles with it (kernels/lattice/band_sweep.h).
#pragma once

#include <cstdint>

#include "kernels/bvh/traversal.h"
#include "kernels/core/vec3.h"

namespace sdf {

/// `leaf(first, count)` is called for every leaf (BVH slots first .. first + count - 1) whose
/// box meets [lo, hi]. The node boxes are float, rounded outward (bvh_node.h): a triangle
/// that meets the box lies in a leaf that is called. An empty child (inverted box) meets none.
template <typename LeafFn>
struct BoxOverlapQuery {
    Vec3d lo, hi;
    LeafFn on_leaf;

    SDF_CPU_GPU SDF_INLINE bool meets(const BvhNode& n, int c) const {
        return double(n.min_x[c]) <= hi.x && double(n.max_x[c]) >= lo.x && double(n.min_y[c]) <= hi.y &&
               double(n.max_y[c]) >= lo.y && double(n.min_z[c]) <= hi.z && double(n.max_z[c]) >= lo.z;
    }
    SDF_CPU_GPU SDF_INLINE ChildOrder<NoKey> measure(const BvhNode& n) const {
        return ChildOrder<NoKey>::ordered(0, NoKey{}, NoKey{}, meets(n, 0), meets(n, 1));
    }
    SDF_CPU_GPU SDF_INLINE bool enter(const NoKey&) const { return true; }
    SDF_CPU_GPU SDF_INLINE void leaf(int32_t first, int32_t count) { on_leaf(first, count); }
    SDF_CPU_GPU SDF_INLINE void node_done() const {}
    SDF_CPU_GPU SDF_INLINE bool still_open(const NoKey&) const { return true; }
};

/// Calls leaf(first, count) for every leaf of `nodes` whose box meets [lo, hi].
template <typename LeafFn>
SDF_CPU_GPU SDF_INLINE void for_each_leaf_meeting_box(const BvhNode* nodes, const Vec3d& lo, const Vec3d& hi, LeafFn leaf) {
    BoxOverlapQuery<LeafFn> q{lo, hi, leaf};
    nearest_first_walk<NoKey>(nodes, q);
}

}  // namespace sdf
