/// @file streamed_certificate.h
/// @brief The certified float search fused into a packet traversal (closest_triangles_packet.h
/// and the GPU warp kernel): the double re-rank happens during the one float search, with
/// two deferred candidates per lane in registers and no candidate list to overflow.
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
/// (which is always offered: its ranked Q is at most its Q, at most radius(Q)): that is t*,
/// certified without any double work. Extra double evaluations of triangles beyond R (a
/// streamed one the radius later passed) never change the argmin: t* is in the set.
///
/// Compared with the separate certify pass (cuda/sampling/certify_kernel.cuh): no second traversal,
/// no candidate array (a fan of any size streams), and double work only where a lane has
/// more than one candidate at once.
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

/// The streamed certificate of a K-lane packet. `PointOf(k)` returns lane k's point in double
/// (the exact point the double search measures from); `exact` holds the double packed
/// triangles in BVH slot order.
template <typename T, int K, typename PointOf>
struct StreamedCertifiedNear {
    static constexpr bool kKeeps = true;
    static constexpr bool kStreams = true;
    static constexpr int kDeferred = 2;

    SearchSlack<T> slack;
    const PackedTriangle<double>* exact = nullptr;
    PointOf point_of;
    int32_t deferred_slot[K][kDeferred];
    T deferred_q[K][kDeferred];  ///< ranked float Q (Q_f - sliver_excess)
    double exact_q[K];           ///< the running double minimum of the streamed triangles
    int32_t exact_triangle[K];   ///< its triangle index (-1: nothing streamed)

    SDF_CPU_GPU StreamedCertifiedNear(const SearchSlack<T>& s, const PackedTriangle<double>* e, PointOf p)
        : slack(s), exact(e), point_of(p) {
        for (int k = 0; k < K; ++k) {
            for (int d = 0; d < kDeferred; ++d) {
                deferred_slot[k][d] = -1;
                deferred_q[k][d] = T(0);
            }
            exact_q[k] = 0.0;
            exact_triangle[k] = -1;
        }
    }

    SDF_CPU_GPU SDF_INLINE T radius(T q) const { return slack.radius(q); }

    /// Folds the triangle in BVH slot `slot` (prepared-mesh index `triangle`) into lane k's
    /// double minimum. Read in place: its 24 doubles need not all be live at once.
    SDF_CPU_GPU SDF_INLINE void fold(int k, int32_t slot, int32_t triangle) {
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

    /// Scans leaf triangles [first, first + count) for every lane: the float best and radius
    /// (refreshed at each improvement), the deferred candidates, the streamed ones. Returns
    /// the largest radius of the packet.
    template <typename Bvh>
    SDF_CPU_GPU SDF_INLINE T scan_leaf(const Bvh& bvh, int32_t first, int32_t count, BvhPacket<T, K>& pk) {
        for (int32_t j = first; j < first + count; ++j) {
            const PackedTriangle<T> tri = bvh.packed[j];
            const int32_t triangle = bvh.triangle_index[j];
            const T excess = sliver_excess(tri);
            unsigned stream = 0;
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
                    stream |= 1u << k;
                }
            }
            while (stream != 0) {
                const int k = detail::lowest_bit(stream);
                stream &= stream - 1;
                fold(k, j, triangle);
            }
        }
        T worst = pk.radius[0];
        for (int k = 1; k < K; ++k) worst = worst > pk.radius[k] ? worst : pk.radius[k];
        return worst;
    }

    /// Lane k's double winner (prepared-mesh triangle index) after the search; `reranked`
    /// tells whether any double evaluation was needed.
    template <typename Bvh>
    SDF_CPU_GPU SDF_INLINE int32_t finish(const Bvh& bvh, int k, const BvhPacket<T, K>& pk, bool& reranked) {
        const T r = pk.radius[k];
        int live = 0;
        for (int d = 0; d < kDeferred; ++d) live += int(deferred_slot[k][d] >= 0 && deferred_q[k][d] <= r);
        reranked = exact_triangle[k] >= 0 || live > 1;
        if (!reranked) return pk.best_triangle[k];
        for (int d = 0; d < kDeferred; ++d) {
            const int32_t s = deferred_slot[k][d];
            if (s >= 0 && deferred_q[k][d] <= r) fold(k, s, bvh.triangle_index[s]);
        }
        return exact_triangle[k];
    }
};

}  // namespace sdf
