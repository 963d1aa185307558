/// @file closest_triangle_bvh.h
/// @brief The exact nearest-triangle query over a BVH, written once for host and device.
///
/// Ordered depth-first traversal with a shrinking radius (traversal.h's nearest_first_walk),
/// the closest-point form of the nearest-neighbour search of Friedman, Bentley & Finkel, "An
/// Algorithm for Finding Best Matches in Logarithmic Expected Time" (ACM TOMS 1977) on the
/// node layout of Aila & Laine (2009): at every node both child boxes are measured, the nearer child is entered first,
/// the farther one is kept on a small fixed stack with its box distance, and an entry is
/// dropped when it is popped if the best squared distance found so far (the radius) has
/// shrunk below it. Leaves are scanned with the same branch-free squared_distance() as the
/// brute-force samplers.
///
/// Exactness. A subtree is skipped only when its box, which contains every one of its
/// triangles, is farther than the best triangle so far by more than the rounding of the two
/// distances (may_hold_nearer's ulps, and in double the view's margin, which bounds how far
/// a computed squared_distance() may fall below the true one: search_certificate.h), so no
/// triangle whose computed distance could beat the best is skipped: the result is the
/// brute-force minimum of squared_distance() with the one tie rule, whatever the tree. A query may be seeded with any triangle (e.g. the winner of a
/// neighbouring lattice point): its distance is a true upper bound, so the seed only
/// shrinks the initial radius and never changes which distance is found.
///
/// Certified float search (search_certificate.h). A `Near` policy sets the pruning radius
/// from the best Q and receives every triangle within it: PlainNear (radius = best, keeps
/// nothing) is the search above; CertifiedNear widens the radius by the float error bound
/// and keeps the candidates, which rerank_in_double() turns into the double search's
/// winner.
#pragma once

#include <limits>

#include "kernels/bvh/aabb_distance.h"
#include "kernels/bvh/bvh_view.h"
#include "kernels/bvh/traversal.h"
#include "kernels/distance/search_certificate.h"

namespace sdf {

/// The nearest triangle found so far: its BVH slot and squared_distance().
template <typename T>
struct BvhHit {
    int32_t slot = -1;
    T distance_squared = std::numeric_limits<T>::infinity();
};

/// Counting hooks for the CPU statistics; the default counts nothing and compiles away.
struct NoBvhStats {
    SDF_CPU_GPU void visit_node() {}
    SDF_CPU_GPU void test_triangles(int) {}
};

struct BvhStats {
    int64_t nodes = 0, triangles = 0;
    SDF_CPU_GPU void visit_node() { ++nodes; }
    SDF_CPU_GPU void test_triangles(int n) { triangles += n; }
};

/// A starting hit from triangle `slot` (BVH order), e.g. a neighbour's winner.
template <typename T>
SDF_CPU_GPU SDF_INLINE BvhHit<T> seed_hit(const BvhView<T>& bvh, int32_t slot, const Vec3<T>& p) {
    BvhHit<T> h;
    if (slot >= 0) {
        h.slot = slot;
        h.distance_squared = squared_distance(bvh.packed[slot], p);
    }
    return h;
}

/// Whether a subtree whose box is `box_d2` away may hold a triangle nearer than `radius`.
/// Both distances are rounded: where the true distances tie (a vertex shared by several
/// triangles is also a corner of their boxes) the box can come out a few ulps beyond a
/// triangle distance that is itself a few ulps below the tie. Entering boxes within 8 ulps
/// of the radius keeps the result the brute-force minimum of the computed distances.
template <typename T>
SDF_CPU_GPU SDF_INLINE bool may_hold_nearer(T box_d2, T radius) {
    return box_d2 <= radius * (T(1) + T(8) * std::numeric_limits<T>::epsilon());
}

/// The one tie rule of every search, CPU and GPU, brute force and BVH: the smaller squared
/// distance wins, and of equal ones the smaller triangle index (prepared-mesh order, which is
/// also the brute-force loop order), so the winner does not depend on the order in which
/// triangles are met: work split, traversal, thread count or GPU model.
SDF_CPU_GPU SDF_INLINE bool wins_tie(int32_t triangle, int32_t best_triangle) {
    return best_triangle < 0 || triangle < best_triangle;
}

/// The plain search: the radius is the best squared distance; nothing is kept.
struct PlainNear {
    static constexpr bool kKeeps = false;
    template <typename T>
    SDF_CPU_GPU SDF_INLINE T radius(T q) const { return q; }
    template <typename T>
    SDF_CPU_GPU SDF_INLINE void offer(int32_t, T) {}
};

/// The certified float search: the radius is the best plus twice the error bound, and every
/// triangle within it is kept as a candidate (search_certificate.h).
template <typename T, int N = kNearCandidates>
struct CertifiedNear {
    static constexpr bool kKeeps = true;
    SearchSlack<T> slack;
    NearCandidates<T, N> near;
    SDF_CPU_GPU SDF_INLINE T radius(T q) const { return slack.radius(q); }
    SDF_CPU_GPU SDF_INLINE void offer(int32_t slot, T q) { near.offer(slot, q); }
};

/// Scans leaf triangles [first, first + count), keeps the nearest in `best` and offers every
/// triangle within `radius` to `near`, which shrinks `radius` as `best` improves.
template <typename T, typename Near>
SDF_CPU_GPU SDF_INLINE void scan_leaf(const BvhView<T>& bvh, int32_t first, int32_t count, const Vec3<T>& p,
                                      BvhHit<T>& best, T& radius, Near& near) {
    for (int32_t j = first; j < first + count; ++j) {
        const PackedTriangle<T>& tri = bvh.packed[j];
        const T q = squared_distance(tri, p);
        if constexpr (Near::kKeeps) {
            const T ranked = q - sliver_excess(tri);
            if (ranked <= radius) near.offer(j, ranked);
        }
        if (q < best.distance_squared ||
            (q == best.distance_squared &&
             wins_tie(bvh.triangle_index[j], best.slot < 0 ? -1 : bvh.triangle_index[best.slot]))) {
            best.distance_squared = q;
            best.slot = j;
            radius = bvh.margin.widen(near.radius(q));
        }
    }
}

template <typename T>
SDF_CPU_GPU SDF_INLINE void scan_leaf(const BvhView<T>& bvh, int32_t first, int32_t count, const Vec3<T>& p,
                                      BvhHit<T>& best) {
    PlainNear plain;
    T radius = best.distance_squared;
    scan_leaf(bvh, first, count, p, best, radius, plain);
}

namespace detail {

/// closest_triangle_bvh()'s query for nearest_first_walk(): children by their box distance,
/// the farther one tested against the radius as it stands after the nearer leaf's scan.
template <typename T, typename Stats, typename Near>
struct NearestTriangleQuery {
    const BvhView<T>& bvh;
    const Vec3<T>& p;
    BvhHit<T>& best;
    T& radius;
    Stats& stats;
    Near& near;
    SDF_CPU_GPU SDF_INLINE ChildOrder<T> measure(const BvhNode& n) {
        stats.visit_node();
        const T d0 = child_box_distance_squared(n, 0, p), d1 = child_box_distance_squared(n, 1, p);
        return ChildOrder<T>::ordered(d1 < d0 ? 1 : 0, d0, d1);
    }
    SDF_CPU_GPU SDF_INLINE bool enter(T key) const { return may_hold_nearer(key, radius); }
    SDF_CPU_GPU SDF_INLINE void leaf(int32_t first, int32_t count) {
        stats.test_triangles(count);
        scan_leaf(bvh, first, count, p, best, radius, near);
    }
    SDF_CPU_GPU SDF_INLINE void node_done() {}
    SDF_CPU_GPU SDF_INLINE bool still_open(T key) const { return may_hold_nearer(key, radius); }
};

}  // namespace detail

/// Nearest triangle to p, starting from `best` (an empty hit or a seed); every triangle
/// within the final radius is offered to `near`.
template <typename T, typename Stats, typename Near>
SDF_CPU_GPU BvhHit<T> closest_triangle_bvh(const BvhView<T>& bvh, const Vec3<T>& p, BvhHit<T> best, Stats& stats,
                                           Near& near) {
    T radius = bvh.margin.widen(near.radius(best.distance_squared));
    detail::NearestTriangleQuery<T, Stats, Near> q{bvh, p, best, radius, stats, near};
    nearest_first_walk<T>(bvh.nodes, q);
    return best;
}

template <typename T, typename Stats>
SDF_CPU_GPU SDF_INLINE BvhHit<T> closest_triangle_bvh(const BvhView<T>& bvh, const Vec3<T>& p, BvhHit<T> best, Stats& stats) {
    PlainNear plain;
    return closest_triangle_bvh(bvh, p, best, stats, plain);
}

template <typename T>
SDF_CPU_GPU SDF_INLINE BvhHit<T> closest_triangle_bvh(const BvhView<T>& bvh, const Vec3<T>& p, BvhHit<T> best = {}) {
    NoBvhStats none;
    return closest_triangle_bvh(bvh, p, best, none);
}

}  // namespace sdf
