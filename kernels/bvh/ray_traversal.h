/// @file ray_traversal.h
/// @brief Closest-hit ray traversal of the triangle BVH (bvh_node.h), written once for host
/// and device: ordered depth-first traversal with a shrinking t_max (traversal.h's
/// nearest_first_walk) on the two-box node layout of Aila & Laine, "Understanding the
/// Efficiency of Ray Traversal on GPUs" (HPG 2009). The ray-box test is the slab method with the far distance enlarged by a few ulps
/// (pbrt-v4's Bounds3::IntersectP, after Ize, "Robust BVH Ray Traversal", JCGT 2013), so a
/// box is never missed by rounding; triangles are tested by the caller's leaf function,
/// which keeps the closest hit and shrinks t_max.
///
///   closest_hit_bvh(nodes, ray, t_max, [&](int32_t first, int32_t count, T& t_max) {
///       for (slot in [first, first + count)) if (hit closer than t_max) { record; t_max = t; }
///   });
///
/// Exactness: a subtree is skipped only when the ray misses its box (which contains every
/// triangle of the subtree) or enters it beyond the closest hit so far, so the result is
/// the closest hit of the leaf function over all triangles.
#pragma once

#include "kernels/bvh/bvh_node.h"
#include "kernels/bvh/traversal.h"
#include "kernels/raycast/camera.h"

namespace sdf {

/// Entry distance of the ray into child c of node n within [0, t_max], or -1 for a miss.
template <typename T>
SDF_CPU_GPU T ray_child_entry(const BvhNode& n, int c, const Ray<T>& ray, const Vec3<T>& inv_dir, T t_max) {
    const T lo[3] = {T(n.min_x[c]), T(n.min_y[c]), T(n.min_z[c])};
    const T hi[3] = {T(n.max_x[c]), T(n.max_y[c]), T(n.max_z[c])};
    // 1 + 2 gamma(3) of the scalar type: covers the rounding of the slab distances
    const T widen = T(1) + T(2) * T(3) * (sizeof(T) == 4 ? T(5.96e-8) : T(1.12e-16)) * T(1.01);
    T t0 = T(0), t1 = t_max;
    for (int a = 0; a < 3; ++a) {
        if (!(lo[a] <= hi[a])) return T(-1);  // empty child
        if (ray.direction[a] == T(0)) {
            if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a]) return T(-1);
            continue;
        }
        T near = (lo[a] - ray.origin[a]) * inv_dir[a], far = (hi[a] - ray.origin[a]) * inv_dir[a];
        if (near > far) { const T tmp = near; near = far; far = tmp; }
        far *= widen;
        t0 = near > t0 ? near : t0;
        t1 = far < t1 ? far : t1;
        if (t0 > t1) return T(-1);
    }
    return t0;
}

namespace detail {

/// closest_hit_bvh()'s query for nearest_first_walk(): children by the ray's entry into their
/// box (-1: missed), entered while the entry is not beyond the closest hit so far.
template <typename T, typename LeafFn>
struct ClosestHitQuery {
    const Ray<T>& ray;
    Vec3<T> inv_dir;
    T& t_max;
    LeafFn& leaf_fn;
    SDF_CPU_GPU SDF_INLINE ChildOrder<T> measure(const BvhNode& n) const {
        const T e0 = ray_child_entry(n, 0, ray, inv_dir, t_max), e1 = ray_child_entry(n, 1, ray, inv_dir, t_max);
        return ChildOrder<T>::ordered((e1 >= T(0) && (e0 < T(0) || e1 < e0)) ? 1 : 0, e0, e1);
    }
    /// The nearer child's entry is within the t_max it was measured with (a NaN t_max, from a
    /// zero direction, ends the walk); the farther one's is compared with t_max as left.
    SDF_CPU_GPU SDF_INLINE bool enter(T entry) const { return still_open(entry); }
    SDF_CPU_GPU SDF_INLINE void leaf(int32_t first, int32_t count) {
        if (count > 0) leaf_fn(first, count, t_max);
    }
    SDF_CPU_GPU SDF_INLINE void node_done() {}
    SDF_CPU_GPU SDF_INLINE bool still_open(T entry) const { return entry >= T(0) && entry <= t_max; }
};

}  // namespace detail

/// Visits the leaves the ray may hit before t_max, nearer child first; `leaf(first, count,
/// t_max)` tests the triangles of one leaf and lowers t_max to the closest hit so far.
template <typename T, typename LeafFn>
SDF_CPU_GPU void closest_hit_bvh(const BvhNode* nodes, const Ray<T>& ray, T t_max, LeafFn&& leaf) {
    const Vec3<T> inv_dir(ray.direction.x != T(0) ? T(1) / ray.direction.x : T(0),
                          ray.direction.y != T(0) ? T(1) / ray.direction.y : T(0),
                          ray.direction.z != T(0) ? T(1) / ray.direction.z : T(0));
    detail::ClosestHitQuery<T, std::remove_reference_t<LeafFn>> q{ray, inv_dir, t_max, leaf};
    nearest_first_walk<T>(nodes, q);
}

}  // namespace sdf
