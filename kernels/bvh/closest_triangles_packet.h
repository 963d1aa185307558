/// @file closest_triangles_packet.h
/// @brief The exact nearest triangle of K neighbouring points in one BVH traversal (a
/// "packet"), written once for host and device: lattice-coherent sampling.
///
/// Neighbouring lattice points have nearly the same candidate triangles, so they share one
/// traversal (packet traversal as in Wald et al., "Interactive Rendering with Coherent Ray
/// Tracing", EG 2001, applied to the closest-point query of closest_triangle_bvh.h). A
/// subtree is entered when its box is nearer to at least one lane than that lane's best
/// squared distance (an active-lane test, K box distances in one vector loop); a subtree
/// waiting on the stack is dropped when its nearest lane is no nearer than the largest
/// best of the packet. In both cases no
/// point of the packet can have a strictly nearer triangle in it, so every point gets the
/// same minimum as its own query would (up to ties and the rounding of T). Leaves test all
/// K points against each triangle: on the CPU that loop over points vectorises (K lanes).
/// Children are entered nearer-first by their nearest lane.
///
/// As closest_triangle_bvh() does with its `Near` policy, a packet search prunes with each
/// lane's radius (PacketPlainNear: its best; PacketCertifiedNear: its best plus the float
/// error bound, search_certificate.h) and offers every triangle within it to the lane's
/// candidates. Radii are refreshed after each leaf: a stale one is larger, so it only keeps
/// more candidates.
#pragma once

#include <cstdint>
#include <type_traits>

#include "kernels/bvh/closest_triangle_bvh.h"
#include "kernels/bvh/traversal.h"

// Vector compares for the leaf loop's lane mask: host compilers with SSE2 (every x86-64), not
// the CUDA compiler's passes.
#if !defined(__CUDACC__) && defined(__SSE2__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define SDF_PACKET_MASK_INTRINSICS 1
#else
#define SDF_PACKET_MASK_INTRINSICS 0
#endif

namespace sdf {

/// K points in structure-of-arrays form with their current best hits. A packet with fewer
/// real points fills the other lanes with copies of a real point (duplicate work, same
/// result), so every loop runs over all K lanes.
template <typename T, int K>
struct BvhPacket {
    T x[K], y[K], z[K];
    T best_q[K];
    int32_t best_slot[K];
    int32_t best_triangle[K];  ///< triangle index of best_slot (-1: none), for the tie rule
    T radius[K];               ///< pruning radius: best_q, or more for a certified search
};

/// The plain packet search: each lane's radius is its best; nothing is kept.
struct PacketPlainNear {
    static constexpr bool kKeeps = false;
    static constexpr bool kStreams = false;
    template <typename T>
    SDF_CPU_GPU SDF_INLINE T radius(T q) const { return q; }
    template <typename T>
    SDF_CPU_GPU SDF_INLINE void offer(int, int32_t, T) {}
};

/// The certified packet search: one error bound for the packet (its largest |coordinate|)
/// and N candidates per lane.
template <typename T, int K, int N = kNearCandidates>
struct PacketCertifiedNear {
    static constexpr bool kKeeps = true;
    static constexpr bool kStreams = false;
    SearchSlack<T> slack;
    NearCandidates<T, N> near[K];
    SDF_CPU_GPU SDF_INLINE T radius(T q) const { return slack.radius(q); }
    SDF_CPU_GPU SDF_INLINE void offer(int lane, int32_t slot, T q) { near[lane].offer(slot, q); }
};

namespace detail {

/// The lanes k with qs[k] <= radius[k] as bit k of a mask (K <= 32). Float packets of 16 on
/// the host compare as whole vectors (one instruction with AVX-512); otherwise lane by lane.
template <typename T, int K>
SDF_CPU_GPU SDF_INLINE uint32_t lanes_within(const T* qs, const T* radius) {
    static_assert(K <= 32, "one bit per lane in a 32-bit mask");
#if SDF_PACKET_MASK_INTRINSICS
    if constexpr (std::is_same_v<T, float> && K == 16) {
#if defined(__AVX512F__)
        return uint32_t(_mm512_cmp_ps_mask(_mm512_loadu_ps(qs), _mm512_loadu_ps(radius), _CMP_LE_OQ));
#elif defined(__AVX__)
        const int lo = _mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(qs), _mm256_loadu_ps(radius), _CMP_LE_OQ));
        const int hi = _mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(qs + 8), _mm256_loadu_ps(radius + 8), _CMP_LE_OQ));
        return uint32_t(lo) | uint32_t(hi) << 8;
#else
        uint32_t m = 0;
        for (int i = 0; i < 4; ++i)
            m |= uint32_t(_mm_movemask_ps(_mm_cmple_ps(_mm_loadu_ps(qs + 4 * i), _mm_loadu_ps(radius + 4 * i)))) << (4 * i);
        return m;
#endif
    }
#endif
    uint32_t m = 0;
    for (int k = 0; k < K; ++k) m |= uint32_t(qs[k] <= radius[k]) << k;
    return m;
}

/// Whether child c's box may hold a nearer triangle for any lane (its distance to that lane
/// is below the lane's best); `min_d2` receives the smallest distance over the lanes.
template <typename T, int K>
SDF_CPU_GPU SDF_INLINE bool child_wanted(const BvhNode& n, int c, const BvhPacket<T, K>& pk, T& min_d2) {
    const T lo_x = T(n.min_x[c]), hi_x = T(n.max_x[c]), lo_y = T(n.min_y[c]), hi_y = T(n.max_y[c]);
    const T lo_z = T(n.min_z[c]), hi_z = T(n.max_z[c]);
    T m = std::numeric_limits<T>::infinity();
#if SDF_PACKET_MASK_INTRINSICS
    if constexpr (std::is_same_v<T, float> && K == 16) {  // the lanes' test as one vector compare
        T d[K], limit[K];
#pragma omp simd reduction(min : m)
        for (int k = 0; k < K; ++k) {
            const T gx = axis_gap(lo_x, hi_x, pk.x[k]), gy = axis_gap(lo_y, hi_y, pk.y[k]), gz = axis_gap(lo_z, hi_z, pk.z[k]);
            d[k] = gx * gx + gy * gy + gz * gz;
            limit[k] = pk.radius[k] * (T(1) + T(8) * std::numeric_limits<T>::epsilon());  // may_hold_nearer()'s
            m = d[k] < m ? d[k] : m;
        }
        min_d2 = m;
        return lanes_within<T, K>(d, limit) != 0;
    }
#endif
    int wanted = 0;
#if !SDF_IS_GPU_CODE
#pragma omp simd reduction(| : wanted) reduction(min : m)
#endif
    for (int k = 0; k < K; ++k) {
        const T gx = axis_gap(lo_x, hi_x, pk.x[k]), gy = axis_gap(lo_y, hi_y, pk.y[k]), gz = axis_gap(lo_z, hi_z, pk.z[k]);
        const T d = gx * gx + gy * gy + gz * gz;
        wanted |= int(may_hold_nearer(d, pk.radius[k]));
        m = d < m ? d : m;
    }
    min_d2 = m;
    return wanted != 0;
}

/// Sets every lane's radius from its best; returns the largest.
template <typename T, int K, typename Near>
SDF_CPU_GPU SDF_INLINE T refresh_radii(const BvhView<T>& bvh, BvhPacket<T, K>& pk, const Near& near) {
#if !SDF_IS_GPU_CODE
#pragma omp simd
#endif
    for (int k = 0; k < K; ++k) pk.radius[k] = bvh.margin.widen(near.radius(pk.best_q[k]));
    T worst = pk.radius[0];
    for (int k = 1; k < K; ++k) worst = worst > pk.radius[k] ? worst : pk.radius[k];
    return worst;
}

/// Offers slot j to the lanes whose Q (`qs`) is within their radius, in lane order: only the
/// lanes of the mask are visited (a tie at a shared vertex makes most leaves offer to some).
template <typename T, int K, typename Near>
SDF_CPU_GPU SDF_INLINE void offer_within(const T* qs, const T* radius, int32_t j, Near& near) {
    for (uint32_t within = lanes_within<T, K>(qs, radius); within != 0; within &= within - 1) {
#if SDF_IS_GPU_CODE
        const int k = __ffs(int(within)) - 1;
#else
        const int k = __builtin_ctz(within);
#endif
        near.offer(k, j, qs[k]);
    }
}

/// squared_distance() in its two forms, for loops whose triangle is the same in every lane:
/// the branch is taken once per triangle, and the lane loop stays one vector loop.
struct BranchFreeDistance {
    template <typename T>
    SDF_CPU_GPU SDF_INLINE T operator()(const PackedTriangle<T>& t, T x, T y, T z) const {
        return branch_free_squared_distance(t, x, y, z);
    }
};
struct SliverDistance {
    template <typename T>
    SDF_CPU_GPU SDF_INLINE T operator()(const PackedTriangle<T>& t, T x, T y, T z) const {
        return sliver_squared_distance(t, x, y, z);
    }
};

/// Tests every lane against triangle `tri` (BVH slot j) with `distance`; qs[k] = Q less the
/// sliver excess (for the offers). Returns whether a best changed.
template <typename T, int K, bool kKeeps, typename Distance>
SDF_CPU_GPU SDF_INLINE int test_lanes(const PackedTriangle<T>& tri, int32_t j, int32_t triangle, T excess,
                                      BvhPacket<T, K>& pk, T* qs, Distance distance) {
    int improved = 0;
#if !SDF_IS_GPU_CODE
#pragma omp simd reduction(| : improved)
#endif
    for (int k = 0; k < K; ++k) {
        const T q = distance(tri, pk.x[k], pk.y[k], pk.z[k]);
        // The tie rule of closest_triangle_bvh.h (wins_tie), lane by lane.
        const bool better = q < pk.best_q[k] ||
                            (q == pk.best_q[k] && (pk.best_triangle[k] < 0 || triangle < pk.best_triangle[k]));
        improved |= int(better);
        pk.best_q[k] = better ? q : pk.best_q[k];
        pk.best_slot[k] = better ? j : pk.best_slot[k];
        pk.best_triangle[k] = better ? triangle : pk.best_triangle[k];
        if constexpr (kKeeps) qs[k] = q - excess;
    }
    return improved;
}

/// Tests every point of the packet against leaf triangles [first, first + count), offering
/// those within a lane's radius to `near`; returns the new largest radius of the packet.
template <typename T, int K, typename Near>
SDF_CPU_GPU SDF_INLINE T scan_leaf_offering(const BvhView<T>& bvh, int32_t first, int32_t count, BvhPacket<T, K>& pk,
                                            Near& near) {
    int improved = 0;
    for (int32_t j = first; j < first + count; ++j) {
        const PackedTriangle<T> tri = bvh.packed[j];
        const int32_t triangle = bvh.triangle_index[j];
        const T excess = Near::kKeeps ? sliver_excess(tri) : T(0);
        T qs[K];
        bool sliver = false;  // squared_distance(): double's slivers by sliver_squared_distance()
        if constexpr (sizeof(T) == sizeof(double)) sliver = is_interior_sliver(tri);
        if (sliver) improved |= test_lanes<T, K, Near::kKeeps>(tri, j, triangle, excess, pk, qs, SliverDistance{});
        else improved |= test_lanes<T, K, Near::kKeeps>(tri, j, triangle, excess, pk, qs, BranchFreeDistance{});
        if constexpr (Near::kKeeps) offer_within<T, K>(qs, pk.radius, j, near);
    }
#if !SDF_IS_GPU_CODE
    // No best changed: the radii, set from the bests after the previous leaf, stand.
    if (!improved) {
        T worst = pk.radius[0];
        for (int k = 1; k < K; ++k) worst = worst > pk.radius[k] ? worst : pk.radius[k];
        return worst;
    }
#else
    (void)improved;
#endif
    return refresh_radii(bvh, pk, near);
}

/// The leaf scan of `near`: offering (above), or a streaming policy's own
/// (streamed_certificate.h), which refreshes the radii itself.
template <typename T, int K, typename Near>
SDF_CPU_GPU SDF_INLINE T scan_leaf_packet(const BvhView<T>& bvh, int32_t first, int32_t count, BvhPacket<T, K>& pk,
                                          Near& near) {
    if constexpr (Near::kStreams) return near.scan_leaf(bvh, first, count, pk);
    else return scan_leaf_offering(bvh, first, count, pk, near);
}

template <typename T, int K>
SDF_CPU_GPU SDF_INLINE T scan_leaf_packet(const BvhView<T>& bvh, int32_t first, int32_t count, BvhPacket<T, K>& pk) {
    PacketPlainNear plain;
    return scan_leaf_packet(bvh, first, count, pk, plain);
}

}  // namespace detail

/// Seeds lane k with triangle seed[k] (BVH slot, or -1 for none): an exact upper bound.
template <typename T, int K>
SDF_CPU_GPU SDF_INLINE void seed_packet(const BvhView<T>& bvh, const int32_t* seed, BvhPacket<T, K>& pk) {
    for (int k = 0; k < K; ++k) {
        pk.best_slot[k] = seed[k];
        pk.best_triangle[k] = seed[k] >= 0 ? bvh.triangle_index[seed[k]] : -1;
        pk.best_q[k] = seed[k] >= 0 ? squared_distance(bvh.packed[seed[k]], pk.x[k], pk.y[k], pk.z[k])
                                    : std::numeric_limits<T>::infinity();
        pk.radius[k] = pk.best_q[k];  // the plain search's; a certified one widens it
    }
}

/// Seeds every lane of `pk` that has a point (best_q >= 0) with the nearest triangle of the
/// leaf its own greedy descent reaches (at each node the child whose box is nearer to the
/// lane's point): one root-to-leaf path per lane, after which a packet or warp walk starts
/// with its radius near its final value, so no lane's search depends on where the other
/// lanes' searches lead first. The radius is set through `near`, as the walk that follows
/// takes the lanes' radii as they are (warp_search does not refresh them). The seed is a best
/// like any other: under a certified policy its leaf lies within the radius (the bound that
/// brings the walk to the double search's triangle), so the walk scans it again and offers
/// it then; the plain search may prune it, and keeps it as its best.
template <typename T, int K, typename Near>
SDF_CPU_GPU SDF_INLINE void seed_by_descent(const BvhView<T>& bvh, BvhPacket<T, K>& pk, const Near& near) {
    for (int k = 0; k < K; ++k) {
        if (!(pk.best_q[k] >= T(0))) continue;  // no point in this lane
        const T x = pk.x[k], y = pk.y[k], z = pk.z[k];
        int32_t node = 0, first = 0, count = 0;
        for (;;) {
            const BvhNode n = bvh.nodes[node];
            T d[2];
            for (int c = 0; c < 2; ++c) {
                const T gx = axis_gap(T(n.min_x[c]), T(n.max_x[c]), x), gy = axis_gap(T(n.min_y[c]), T(n.max_y[c]), y);
                const T gz = axis_gap(T(n.min_z[c]), T(n.max_z[c]), z);
                d[c] = gx * gx + gy * gy + gz * gz;
            }
            const bool second = d[1] < d[0];  // an empty child's inverted box is +inf away
            const int32_t ref = second ? n.ref[1] : n.ref[0];
            count = second ? n.count[1] : n.count[0];
            if (bvh_child_is_leaf(ref, count)) {
                first = ref;
                break;
            }
            node = ref;
        }
        for (int32_t j = first; j < first + count; ++j) {
            const T q = squared_distance(bvh.packed[j], x, y, z);
            const int32_t triangle = bvh.triangle_index[j];
            if (q < pk.best_q[k] || (q == pk.best_q[k] && wins_tie(triangle, pk.best_triangle[k]))) {
                pk.best_q[k] = q;
                pk.best_slot[k] = j;
                pk.best_triangle[k] = triangle;
            }
        }
        pk.radius[k] = bvh.margin.widen(near.radius(pk.best_q[k]));
    }
}

namespace detail {

/// closest_triangles_packet()'s query for nearest_first_walk(): a child is wanted when it is
/// within some lane's radius (decided for both children on entering the node), ordered and
/// stacked by its nearest lane's distance, a lower bound for every lane; a stacked subtree
/// is dropped once that distance is beyond every lane's radius.
template <typename T, int K, typename Stats, typename Near>
struct NearestTrianglesPacketQuery {
    const BvhView<T>& bvh;
    BvhPacket<T, K>& pk;
    T& worst;  ///< the largest radius of the packet
    Stats& stats;
    Near& near;
    SDF_CPU_GPU SDF_INLINE ChildOrder<T> measure(const BvhNode& n) {
        stats.visit_node();
        T d0, d1;
        const bool want0 = child_wanted(n, 0, pk, d0), want1 = child_wanted(n, 1, pk, d1);
        return ChildOrder<T>::ordered(d1 < d0 ? 1 : 0, d0, d1, want0, want1);
    }
    SDF_CPU_GPU SDF_INLINE bool enter(T) const { return true; }  // the votes decided
    SDF_CPU_GPU SDF_INLINE void leaf(int32_t first, int32_t count) {
        stats.test_triangles(count * K);
        worst = scan_leaf_packet(bvh, first, count, pk, near);
    }
    SDF_CPU_GPU SDF_INLINE void node_done() {}
    SDF_CPU_GPU SDF_INLINE bool still_open(T key) const { return may_hold_nearer(key, worst); }
};

}  // namespace detail

/// Completes the nearest triangle of every lane of `pk` (seeded or with infinite radii),
/// offering every triangle within a lane's final radius to `near`.
template <typename T, int K, typename Stats, typename Near>
SDF_CPU_GPU void closest_triangles_packet(const BvhView<T>& bvh, BvhPacket<T, K>& pk, Stats& stats, Near& near) {
    T worst = detail::refresh_radii(bvh, pk, near);
    detail::NearestTrianglesPacketQuery<T, K, Stats, Near> q{bvh, pk, worst, stats, near};
    nearest_first_walk<T>(bvh.nodes, q);
}

template <typename T, int K, typename Stats>
SDF_CPU_GPU SDF_INLINE void closest_triangles_packet(const BvhView<T>& bvh, BvhPacket<T, K>& pk, Stats& stats) {
    PacketPlainNear plain;
    closest_triangles_packet(bvh, pk, stats, plain);
}

}  // namespace sdf
