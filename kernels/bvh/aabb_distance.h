/// @file aabb_distance.h
/// @brief Squared distance from a point to an axis-aligned box: the lower bound that lets a
/// closest-point query skip a subtree (Ericson, "Real-Time Collision Detection", 5.1.3).
///
/// Per axis the gap is max(lo - p, 0, p - hi); the squared distance is the sum of squared
/// gaps. It is exact up to the rounding of T and never exceeds the distance to anything
/// inside the box; an inverted (empty) box gives +inf.
#pragma once

#include "kernels/bvh/bvh_node.h"
#include "kernels/core/vec3.h"

namespace sdf {

template <typename T>
SDF_CPU_GPU SDF_INLINE T axis_gap(T lo, T hi, T p) {
    const T below = T(lo) - p, above = p - T(hi);
    const T g = below > above ? below : above;
    return g > T(0) ? g : T(0);
}

/// Squared distance from p to child c of node n (0 inside the box).
template <typename T>
SDF_CPU_GPU SDF_INLINE T child_box_distance_squared(const BvhNode& n, int c, const Vec3<T>& p) {
    const T gx = axis_gap(T(n.min_x[c]), T(n.max_x[c]), p.x);
    const T gy = axis_gap(T(n.min_y[c]), T(n.max_y[c]), p.y);
    const T gz = axis_gap(T(n.min_z[c]), T(n.max_z[c]), p.z);
    return gx * gx + gy * gy + gz * gz;
}

}  // namespace sdf
