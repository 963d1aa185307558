/// @file streamed_certificate.h
/// @brief The certified float search fused into a packet traversal (closest_triangles_packet.h
/// and the GPU warp kernel): two deferred candidates per lane in registers, and the double
/// re-rank during the one float search (streamed) or right after it (listed).
///
/// Why it is exact. Let t* be the double search's winner (search_certificate.h). Its ranked
/// float Q (Q_f - sliver_excess) is within the final radius R = radius(q_best), and the
/// radius only shrinks, so t* is within the lane's radius whenever it is scanned, and the
/// certified pruning (radius R) reaches its leaf. The argmin of the double Q with the one tie
/// rule over ANY set that holds t* is t* itself. So every triangle met within the current
/// radius is either
///   - deferred (two slots per lane); a deferred one is forgotten only once it lies beyond
///     the current radius, which t* never does, or
///   - evaluated in double at once ("streamed") when both slots hold live candidates, its
///     double Q folded into the lane's running double minimum;
/// and at the end the deferred ones within R are evaluated and folded in too. A lane that
/// streamed nothing and ends with one deferred candidate within R has only the float winner
/// (which is always offered: its ranked Q is at most its Q, at most radius(Q); a seeded best,
/// seed_by_descent, is offered when the walk meets it again, as its leaf is within the
/// certified radius by the same bound that brings the walk to t*): that is t*, certified
/// without any double work. Extra double evaluations of triangles beyond R (a
/// streamed one the radius later passed) never change the argmin: t* is in the set.
///
/// Compared with the separate certify pass (cuda/sampling/certify_kernel.cuh): no second traversal,
/// no candidate array (a fan of any size streams), and double work only where a lane has
/// more than one candidate at once.
///
/// Listed instead of streamed (NearListAppend, the GPU's point lists): a triangle that finds
/// both slots live is written to the point's list in memory, and at the end so are the live
/// deferred ones; rerank_near_list() then re-ranks the list's triangles within R in double in
/// a pass of its own, so the walk carries no double state, and leaves them to the winding
/// sign's nearest_side(). The same argument holds: every triangle whose ranked Q is within R
/// was met within the radius of its time, and is in the list or deferred at the end (a full
/// list drops only entries beyond the radius of their time, or, remembering the smallest Q
/// it dropped, its largest); a list that had to drop one within R sends its point to the
/// separate pass's seeded certified search.
#pragma once

#include "kernels/bvh/closest_triangles_packet.h"

// Lanes are indexed only in fully unrolled loops, so the device keeps the per-lane arrays in
// registers (a run-time index would move them to local memory).
#if SDF_IS_GPU_CODE
#define SDF_UNROLL_LANES _Pragma("unroll")
#else
#define SDF_UNROLL_LANES
#endif

namespace sdf {

namespace detail {

/// Index of the lowest set bit of a nonzero mask.
SDF_CPU_GPU SDF_INLINE int lowest_bit(unsigned mask) {
#if SDF_IS_GPU_CODE
    return __ffs(int(mask)) - 1;
#else
    return __builtin_ctz(mask);
#endif
}

}  // namespace detail

/// What a lane does with a candidate that finds both deferred slots live: FoldInDouble
/// evaluates it in double at once, NearListAppend writes it to the point's list for a
/// re-rank after the search (below).
///
/// The deferral shared by both: two candidates per lane in registers, the float best and
/// radius refreshed at each improvement. `PointOf(k)` returns lane k's point in double (the
/// exact point the double search measures from).
template <typename T, int K, typename PointOf, typename Spill>
struct DeferredCertifiedNear {
    static constexpr bool kKeeps = true;
    static constexpr bool kStreams = true;
    static constexpr int kDeferred = 2;

    SearchSlack<T> slack;
    PointOf point_of;
    Spill spill;
    int32_t deferred_slot[K][kDeferred];
    T deferred_q[K][kDeferred];  ///< ranked float Q (Q_f - sliver_excess)

    SDF_CPU_GPU DeferredCertifiedNear(const SearchSlack<T>& s, PointOf p, Spill sp) : slack(s), point_of(p), spill(sp) {
        for (int k = 0; k < K; ++k)
            for (int d = 0; d < kDeferred; ++d) {
                deferred_slot[k][d] = -1;
                deferred_q[k][d] = T(0);
            }
    }

    SDF_CPU_GPU SDF_INLINE T radius(T q) const { return slack.radius(q); }

    /// Scans leaf triangles [first, first + count) for every lane: the float best and radius
    /// (refreshed at each improvement), the deferred candidates, the spilled ones. Returns
    /// the largest radius of the packet.
    template <typename Bvh>
    SDF_CPU_GPU SDF_INLINE T scan_leaf(const Bvh& bvh, int32_t first, int32_t count, BvhPacket<T, K>& pk) {
        for (int32_t j = first; j < first + count; ++j) {
            const PackedTriangle<T> tri = bvh.packed[j];
            const int32_t triangle = bvh.triangle_index[j];
            const T excess = sliver_excess(tri);
            unsigned spilled = 0;
            T spilled_q[K];
            SDF_UNROLL_LANES
            for (int k = 0; k < K; ++k) {
                const T q = squared_distance(tri, pk.x[k], pk.y[k], pk.z[k]);
                if (q < pk.best_q[k] || (q == pk.best_q[k] && wins_tie(triangle, pk.best_triangle[k]))) {
                    pk.best_q[k] = q;
                    pk.best_slot[k] = j;
                    pk.best_triangle[k] = triangle;
                    pk.radius[k] = slack.radius(q);
                }
                const T ranked = q - excess;
                spilled_q[k] = ranked;
                const T r = pk.radius[k];
                if (!(ranked <= r)) continue;
                // A slot is free when empty or when its candidate is beyond the radius now.
                if (deferred_slot[k][0] < 0 || !(deferred_q[k][0] <= r)) {
                    deferred_slot[k][0] = j;
                    deferred_q[k][0] = ranked;
                } else if (deferred_slot[k][1] < 0 || !(deferred_q[k][1] <= r)) {
                    deferred_slot[k][1] = j;
                    deferred_q[k][1] = ranked;
                } else {
                    spilled |= 1u << k;
                }
            }
            while (spilled != 0) {
                const int k = detail::lowest_bit(spilled);
                spilled &= spilled - 1;
                T ranked = spilled_q[0];  // spilled_q[k], k a run-time value: a select over the unrolled lanes
                SDF_UNROLL_LANES
                for (int l = 1; l < K; ++l) ranked = l == k ? spilled_q[l] : ranked;
                T r = pk.radius[0];
                SDF_UNROLL_LANES
                for (int l = 1; l < K; ++l) r = l == k ? pk.radius[l] : r;
                spill.take(point_of, k, j, triangle, ranked, r);
            }
        }
        T worst = pk.radius[0];
        for (int k = 1; k < K; ++k) worst = worst > pk.radius[k] ? worst : pk.radius[k];
        return worst;
    }

    /// Lane k's triangle after the search (prepared-mesh index): FoldInDouble's double
    /// winner, NearListAppend's float winner (the re-rank replaces it). `reranked` tells
    /// whether double evaluations were needed (FoldInDouble only).
    template <typename Bvh>
    SDF_CPU_GPU SDF_INLINE int32_t finish(const Bvh& bvh, int k, const BvhPacket<T, K>& pk, bool& reranked) {
        const T r = pk.radius[k];
        unsigned live = 0;  // bit d: deferred slot d is within the final radius
        for (int d = 0; d < kDeferred; ++d) live |= unsigned(deferred_slot[k][d] >= 0 && deferred_q[k][d] <= r) << d;
        return spill.finish(bvh, point_of, k, pk, deferred_slot[k], deferred_q[k], live, reranked);
    }
};

/// The fused certificate's spill in double: the lane's running double minimum of the
/// triangles that found both deferred slots live; at the end the live deferred ones are
/// folded in too, unless nothing was spilled and one is left (the float winner).
template <int K>
struct FoldInDouble {
    const PackedTriangle<double>* exact = nullptr;  ///< double packed triangles in BVH slot order
    double exact_q[K];          ///< the running double minimum of the spilled triangles
    int32_t exact_triangle[K];  ///< its triangle index (-1: nothing spilled)

    SDF_CPU_GPU explicit FoldInDouble(const PackedTriangle<double>* e) : exact(e) {
        for (int k = 0; k < K; ++k) {
            exact_q[k] = 0.0;
            exact_triangle[k] = -1;
        }
    }

    /// Folds the triangle in BVH slot `slot` (prepared-mesh index `triangle`) into lane k's
    /// double minimum. Read in place: its 24 doubles need not all be live at once.
    template <typename PointOf, typename T>
    SDF_CPU_GPU SDF_INLINE void take(const PointOf& point_of, int k, int32_t slot, int32_t triangle, T, T) {
        const Vec3d p = point_of(k);
        const double d = squared_distance(exact[slot], p.x, p.y, p.z);
        // k may be a run-time value: a select over the unrolled lanes.
        SDF_UNROLL_LANES
        for (int l = 0; l < K; ++l) {
            if (l != k) continue;
            if (exact_triangle[l] < 0 || d < exact_q[l] || (d == exact_q[l] && triangle < exact_triangle[l])) {
                exact_q[l] = d;
                exact_triangle[l] = triangle;
            }
        }
    }

    /// `live`: bit d set where deferred `slot[d]` is within the final radius.
    template <typename Bvh, typename PointOf, typename T, int D>
    SDF_CPU_GPU SDF_INLINE int32_t finish(const Bvh& bvh, const PointOf& point_of, int k, const BvhPacket<T, K>& pk,
                                          const int32_t (&slot)[D], const T (&)[D], unsigned live, bool& reranked) {
        reranked = exact_triangle[k] >= 0 || (live & (live - 1)) != 0;
        if (!reranked) return pk.best_triangle[k];
        for (int d = 0; d < D; ++d)
            if (live >> d & 1u) take(point_of, k, slot[d], bvh.triangle_index[slot[d]], 0.0, 0.0);
        return exact_triangle[k];
    }
};

/// The fused certificate of a K-lane packet with its spill in double (the lattices').
template <typename T, int K, typename PointOf>
struct StreamedCertifiedNear : DeferredCertifiedNear<T, K, PointOf, FoldInDouble<K>> {
    SDF_CPU_GPU StreamedCertifiedNear(const SearchSlack<T>& s, const PackedTriangle<double>* e, PointOf p)
        : DeferredCertifiedNear<T, K, PointOf, FoldInDouble<K>>(s, p, FoldInDouble<K>(e)) {}
};

/// Candidates a listed certificate keeps per point by default (NearLists::slots); a point
/// with more within its final radius (a vertex of that many triangles within the bound)
/// takes the separate pass's wide certified search (certify_kernel.cuh, counted as
/// full_double).
constexpr int kNearListSlots = 16;

/// Per point of a search (index i < rows), what the listed certificate leaves for the
/// re-rank (rerank_near_list): up to `slots` candidates (BVH slots, ranked float Q), entry
/// c at [c * rows + i] (so a warp's consecutive points read and write consecutive words),
/// how many it holds (slots + 1: overflowed), and the float winner's Q. After the re-rank
/// `slot` holds the live candidates' triangle indices (the winner among them) and `count`
/// their number (0: unknown, an overflow): nearest_side()'s NearTriangles.
struct NearLists {
    int32_t* slot = nullptr;
    float* q = nullptr;
    int32_t* count = nullptr;
    float* best_q = nullptr;
    int slots = kNearListSlots;  ///< entries per point
    int64_t rows = 0;            ///< points the arrays hold: the stride between a point's entries
    SDF_CPU_GPU bool enabled() const { return slot != nullptr; }
};

/// The fused certificate's spill to memory: lane k (point row + k, a real point where k <
/// real) appends the candidates that find both deferred slots live to its list, and at the
/// end its live deferred ones; the double work is left to rerank_near_list, off the walk.
///
/// A full list first drops the entries beyond the lane's current radius (stale: the radius
/// only shrinks, so they lie beyond the final one too). Still full, it keeps the `slots`
/// smallest ranked Q of the list and the new entry and remembers the smallest Q it dropped:
/// the list overflows only where that one lies within the final radius (more than `slots`
/// candidates at the end, a vertex of that many triangles), not where
/// the radius was still large when the list filled (a point far from the surface).
template <int K>
struct NearListAppend {
    NearLists lists;
    int64_t row = 0;  ///< the list of lane 0's point
    int real = 0;     ///< lanes [0, real) hold points; the others repeat lane 0's
    int32_t listed[K];
    float dropped[K];  ///< the smallest ranked Q dropped from a full list (+inf: none)

    SDF_CPU_GPU NearListAppend(const NearLists& l, int64_t first, int count) : lists(l), row(first), real(count) {
        for (int k = 0; k < K; ++k) {
            listed[k] = 0;
            dropped[k] = INFINITY;
        }
    }

    /// Appends to lane k's list, `radius` the lane's current one.
    SDF_CPU_GPU SDF_INLINE void append(int k, int32_t slot, float q, float radius) {
        SDF_UNROLL_LANES
        for (int l = 0; l < K; ++l) {
            if (l != k) continue;
            const int full = lists.slots;
            const int64_t stride = lists.rows;
            int32_t* slots = lists.slot + (row + l);
            float* qs = lists.q + (row + l);
            if (listed[l] < full) {
                slots[listed[l] * stride] = slot;
                qs[listed[l]++ * stride] = q;
                continue;
            }
            // Full: this thread's own writes, read back in order.
            int kept = 0, largest = 0;
            float largest_q = 0;
            for (int c = 0; c < full; ++c) {
                const float qc = qs[c * stride];
                if (qc <= radius) {
                    slots[kept * stride] = slots[c * stride];
                    qs[kept * stride] = qc;
                    if (kept == 0 || qc > largest_q) {
                        largest = kept;
                        largest_q = qc;
                    }
                    ++kept;
                }
            }
            if (kept < full) {
                slots[kept * stride] = slot;
                qs[kept++ * stride] = q;
            } else if (q < largest_q) {
                dropped[l] = fminf(dropped[l], largest_q);
                slots[largest * stride] = slot;
                qs[largest * stride] = q;
            } else {
                dropped[l] = fminf(dropped[l], q);
            }
            listed[l] = kept;
        }
    }

    template <typename PointOf, typename T>
    SDF_CPU_GPU SDF_INLINE void take(const PointOf&, int k, int32_t slot, int32_t, T q, T radius) {
        if (k < real) append(k, slot, float(q), float(radius));
    }

    /// Writes lane k's count (lists.slots + 1: overflowed) and winner's Q.
    template <typename Bvh, typename PointOf, typename T, int D>
    SDF_CPU_GPU SDF_INLINE int32_t finish(const Bvh&, const PointOf&, int k, const BvhPacket<T, K>& pk,
                                          const int32_t (&slot)[D], const T (&q)[D], unsigned live, bool& reranked) {
        reranked = false;
        if (k >= real) return pk.best_triangle[k];
        const float radius = float(pk.radius[k]);
        for (int d = 0; d < D; ++d)
            if (live >> d & 1u) append(k, slot[d], float(q[d]), radius);
        int32_t n = 0;
        float lost = INFINITY;
        SDF_UNROLL_LANES
        for (int l = 0; l < K; ++l) {
            n = l == k ? listed[l] : n;
            lost = l == k ? dropped[l] : lost;
        }
        lists.count[row + k] = lost <= radius ? lists.slots + 1 : n;
        lists.best_q[row + k] = float(pk.best_q[k]);
        return pk.best_triangle[k];
    }
};

/// The fused certificate of a K-lane packet with its spill listed (point lists).
template <typename T, int K, typename PointOf>
struct ListedCertifiedNear : DeferredCertifiedNear<T, K, PointOf, NearListAppend<K>> {
    SDF_CPU_GPU ListedCertifiedNear(const SearchSlack<T>& s, PointOf p, const NearLists& lists, int64_t first, int count)
        : DeferredCertifiedNear<T, K, PointOf, NearListAppend<K>>(s, p, NearListAppend<K>(lists, first, count)) {}
};

/// Point i's double search triangle from its list (NearListAppend) and its float winner
/// `winner` (prepared-mesh index): the live candidates (ranked Q within the final radius)
/// re-ranked in double at the exact point p, ties to the smaller index, as
/// rerank_in_double(); an overflowed list takes `full_search(p)` (any search that returns the
/// double search's triangle index: on the GPU the separate pass's, seeded with the winner).
/// Leaves the live candidates' triangles in the list for nearest_side(). `reranked`: more
/// than one live candidate, or an overflow.
template <typename FullSearch>
SDF_CPU_GPU inline int32_t rerank_near_list(const NearLists& lists, int64_t i, const SearchSlack<float>& slack,
                                            const PackedTriangle<double>* exact, const int32_t* triangle_index,
                                            const Vec3d& p, int32_t winner, FullSearch full_search, bool& reranked,
                                            bool& overflow) {
    const int32_t offered = lists.count[i];
    overflow = offered > lists.slots;
    reranked = overflow;
    if (overflow) {
        lists.count[i] = 0;
        return full_search(p);
    }
    const int64_t stride = lists.rows;
    int32_t* slot = lists.slot + i;
    const float* q = lists.q + i;
    const float r = slack.radius(lists.best_q[i]);
    int live = 0;
    for (int c = 0; c < offered; ++c)
        if (q[c * stride] <= r) slot[live++ * stride] = slot[c * stride];
    reranked = live > 1;
    double best = 0;
    int32_t best_triangle = winner;
    for (int c = 0; c < live; ++c) {
        const int32_t s = slot[c * stride];
        const int32_t triangle = triangle_index[s];
        if (reranked) {
            const double d = squared_distance(exact[s], p.x, p.y, p.z);
            if (c == 0 || d < best || (d == best && triangle < best_triangle)) {
                best = d;
                best_triangle = triangle;
            }
        }
        slot[c * stride] = triangle;
    }
    SDF_DCHECK(live != 1 || slot[0] == winner);  // one live candidate: the float winner itself
    lists.count[i] = live;
    return best_triangle;
}


}  // namespace sdf
