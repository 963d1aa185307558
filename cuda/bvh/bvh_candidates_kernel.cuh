/// @file bvh_candidates_kernel.cuh
/// @brief Kernel "candidates" (issue 14): the 128 points of a warp (a lattice brick of
/// 8 x 4 x 4, or 128 Morton-consecutive points of a list) share one candidate list, found by
/// one traversal with a fixed radius, and every point then scans that list at the
/// brute-force kernel's pair rate; no per-point pruning, no votes, no shrinking radii.
///
/// Exactness. Let t_c be the nearest triangle of the brick box's centre c and u the largest
/// squared distance from a point p of the brick to t_c. Each point's own winner t* has
/// q(p, t*) <= q(p, t_c) <= u. A leaf box B holding t* has box_d2(B, brick) <= box_d2(B, p)
/// (the brick box holds p, and float subtraction is monotone, so this holds as computed) and
/// box_d2(B, p) is within may_hold_nearer's 8 ulps of q(p, t*) plus the view's margin (in
/// double; search_certificate.h's PruneMargin), the premise every BVH search of the project
/// rests on (closest_triangle_bvh.h). So every leaf with
/// may_hold_nearer(box_d2(B, brick), margin.widen(u)) is a candidate, t* is among them, and the minimum
/// over the candidates with the one tie rule is the brute-force winner, bit for bit.
///
/// Narrow band (SamplerOptions::band_width w). By 1-Lipschitz continuity every point of the
/// brick has |d(p)| >= |d(c)| - |p - c|; when that bound (with a rounding allowance relative
/// to the coordinates) exceeds w, the whole brick lies outside the band: no list, no scan,
/// and its points are marked with the side of c (pseudonormal sign: the brick does not cross
/// the surface) or "sign per point" (winding sign, whose side may change away from the
/// surface), which finalize_samples() turns into the band's value.
#pragma once

#include "cuda/bvh/bvh_warp_kernel.cuh"
#include "kernels/bvh/traversal.h"

namespace sdf::cuda {

/// Leaf ranges a warp holds before it scans them; more are scanned in rounds (same result).
constexpr int kCandidateRanges = 96;

/// Optional counters (nullptr: none): [0] bricks searched, [1] candidate triangles scanned
/// per point summed over bricks, [2] bricks outside the band, [3] leaf ranges.
using CandidateStats = unsigned long long*;

namespace detail {

/// Squared gap between the brick box and child c of node n (0 when they overlap).
template <typename T>
__device__ SDF_INLINE T brick_gap_d2(const BvhNode& n, int c, const Vec3<T>& lo, const Vec3<T>& hi) {
    const auto gap = [](T node_lo, T node_hi, T brick_lo, T brick_hi) {
        const T below = node_lo - brick_hi, above = brick_lo - node_hi;
        const T g = below > above ? below : above;
        return g > T(0) ? g : T(0);
    };
    const T gx = gap(T(n.min_x[c]), T(n.max_x[c]), lo.x, hi.x);
    const T gy = gap(T(n.min_y[c]), T(n.max_y[c]), lo.y, hi.y);
    const T gz = gap(T(n.min_z[c]), T(n.max_z[c]), lo.z, hi.z);
    return gx * gx + gy * gy + gz * gz;
}

/// The candidates kernel's query for nearest_first_walk(): every leaf within u of the brick
/// box, whose ranges lane 0 collects for the warp (scanned in rounds of kCandidateRanges).
/// The radius never shrinks, so the children keep their own order and every stacked subtree
/// stays open.
template <typename T, typename Scan>
struct CandidateQuery {
    const Vec3<T>& lo;
    const Vec3<T>& hi;
    T u;
    Scan& scan;
    int32_t* range_first;  ///< this warp's, in shared memory
    int32_t* range_count;
    int& ranges;
    int& triangles;
    int lane;
    __device__ SDF_INLINE ChildOrder<NoKey> measure(const BvhNode& n) const {
        ChildOrder<NoKey> c;  // child 0 first
        c.near_wanted = may_hold_nearer(brick_gap_d2(n, 0, lo, hi), u);
        c.far_wanted = may_hold_nearer(brick_gap_d2(n, 1, lo, hi), u);
        return c;
    }
    __device__ SDF_INLINE bool enter(const NoKey&) const { return true; }
    __device__ SDF_INLINE void leaf(int32_t first, int32_t count) {
        if (count <= 0) return;
        if (lane == 0) {
            range_first[ranges] = first;
            range_count[ranges] = count;
        }
        triangles += count;
        if (++ranges == kCandidateRanges) scan();
    }
    __device__ SDF_INLINE void node_done() {}
    __device__ SDF_INLINE bool still_open(const NoKey&) const { return true; }
};

}  // namespace detail

template <typename T, typename Layout>
__global__ void __launch_bounds__(kBvhThreads) nearest_triangle_bvh_candidates(BvhView<T> bvh, Layout layout, BandSearch band,
                                                                                int* nearest, CandidateStats stats) {
    constexpr int kWarps = kBvhThreads / 32;
    __shared__ int32_t stack_node[kWarps][kBvhMaxDepth];
    __shared__ int32_t range_first[kWarps][kCandidateRanges];
    __shared__ int32_t range_count[kWarps][kCandidateRanges];
    const int w = threadIdx.x / 32, lane = threadIdx.x % 32;

    const int64_t t = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    int64_t first = 0;
    BvhPacket<T, kRunPoints> pk;
    const int count = load_packet<T>(layout, t, first, pk);

    Vec3<T> lo, hi;
    warp_brick_box(pk, count, lo, hi);
    if (!(lo.x <= hi.x)) return;  // no point in this warp
    const Vec3<T> c((lo.x + hi.x) / T(2), (lo.y + hi.y) / T(2), (lo.z + hi.z) / T(2));

    // The centre's nearest triangle: every lane walks the same path (broadcast loads).
    const BvhHit<T> seed = closest_triangle_bvh(bvh, c);
    if (band.width > 0 && band.skip_bricks) {
        const int code = brick_band_code(bvh, pk, count, c, seed, band);
        if (code != 0) {
            for (int k = 0; k < count; ++k) nearest[first + k] = code;
            if (stats && lane == 0) atomicAdd(stats + 2, 1ull);
            return;
        }
    }

    // u: the largest squared distance of a brick point to the seed, a bound on every winner's.
    const PackedTriangle<T> seed_triangle = bvh.packed[seed.slot];
    T u = T(-1);
    for (int k = 0; k < count; ++k) u = max(u, squared_distance(seed_triangle, pk.x[k], pk.y[k], pk.z[k]));
    u = bvh.margin.widen(warp_max(u));  // the double search's margin (zero in float)

    int ranges = 0, triangles = 0, rounds_ranges = 0;  // warp-uniform
    const auto scan_ranges = [&]() {
        __syncwarp();
        for (int r = 0; r < ranges; ++r) sdf::detail::scan_leaf_packet(bvh, range_first[w][r], range_count[w][r], pk);
        rounds_ranges += ranges;
        ranges = 0;
        __syncwarp();
    };
    // Every leaf within u of the brick, in the children's own order.
    detail::CandidateQuery<T, decltype(scan_ranges)> q{lo, hi, u, scan_ranges, range_first[w], range_count[w], ranges, triangles, lane};
    detail::WarpStack<NoKey> stack{stack_node[w], nullptr};
    nearest_first_walk<NoKey>(bvh.nodes, q, stack);
    scan_ranges();
    if (stats && lane == 0) {
        atomicAdd(stats + 0, 1ull);
        atomicAdd(stats + 1, (unsigned long long)triangles);
        atomicAdd(stats + 3, (unsigned long long)rounds_ranges);
    }
    for (int k = 0; k < count; ++k) nearest[first + k] = bvh.triangle_index[pk.best_slot[k]];
}

}  // namespace sdf::cuda
