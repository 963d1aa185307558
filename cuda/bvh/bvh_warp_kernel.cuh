/// @file bvh_warp_kernel.cuh
/// @brief BVH search with one traversal per warp: the 32 threads of a warp (a compact 8 x 4 x
/// 4 brick of lattice points, 4 points per thread, as in bvh_kernel.cuh) walk the tree
/// together, so node loads are broadcasts and the warp never diverges in the traversal.
///
/// The same exactness argument as closest_triangles_packet.h, over 128 points instead of 4:
/// a child is entered when its box is nearer to at least one point than that point's best
/// squared distance (a warp vote), and a subtree on the stack is dropped only when its
/// nearest point is no nearer than the largest best of the warp. Every point therefore gets
/// its own exact minimum (up to ties). Leaves are scanned by every thread for its 4 points.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <type_traits>
#include <utility>

#include "kernels/bvh/closest_triangles_packet.h"
#include "kernels/bvh/streamed_certificate.h"
#include "kernels/bvh/traversal.h"
#include "cuda/bvh/bvh_kernel.cuh"
#include "cuda/sampling/certify_kernel.cuh"
#include "cuda/sampling/finalize_kernel.cuh"
#include "cuda/util/warp_reduce.cuh"
#include "kernels/distance/signed_distance.h"

namespace sdf::cuda {

/// Where a warp's points come from: thread t owns `count` consecutive piece-local ids from
/// `first` (count 0: none). A lattice slab gives every warp an 8 x 4 x 4 brick (SlabGeometry);
/// a point list sorted into Morton order gives it 128 consecutive points, which are then
/// neighbours in space as well (kernels/core/morton.h).
struct SlabLayout {
    static constexpr int kPoints = kRunPoints;  ///< points per thread
    GridRangePiece piece;
    SlabGeometry slab;
    SDF_CPU_GPU int64_t threads() const { return slab.threads(); }
    SDF_CPU_GPU int points_of(int64_t t, int64_t& first) const {
        first = 0;
        if (t >= slab.threads()) return 0;
        const Int3 s = slab.run_start(t);
        if (s.x >= slab.resolution.x || s.y >= slab.resolution.y || s.z >= slab.nz) return 0;
        first = s.x + int64_t(slab.resolution.x) * (s.y + int64_t(slab.resolution.y) * s.z);
        return min(kRunPoints, slab.resolution.x - s.x);
    }
    SDF_CPU_GPU Vec3d position(int64_t i) const { return piece.position(i); }
};

/// A sorted point list, K consecutive points per thread (32 K per warp).
template <int K>
struct ListRuns {
    static constexpr int kPoints = K;
    static constexpr bool kListsCandidates = true;  ///< the certificate may list (lists_candidates)
    PointListPiece piece;
    /// Each lane's search seeded by its own root-to-leaf descent (seed_by_descent) before
    /// the warp's walk. Morton order keeps most batches compact, but where the list is
    /// sparse (points far off the surface, a jump of the curve) 32 consecutive points can lie
    /// across the mesh; unseeded, the lanes far from where the shared walk went first kept
    /// radii of that size, and the warp walked the union of those searches: one batch of a
    /// 1M-point list outlasted all the others by 0.9 ms (docs/gpu-notes.md).
    bool seeded = true;
    SDF_CPU_GPU int64_t threads() const { return (piece.size() + K - 1) / K; }
    SDF_CPU_GPU int points_of(int64_t t, int64_t& first) const {
        first = t * K;
        const int64_t left = piece.size() - first;
        if (left <= 0) first = 0;
        return left <= 0 ? 0 : int(left < K ? left : K);
    }
    SDF_CPU_GPU Vec3d position(int64_t i) const { return piece.position(i); }
};
using ListLayout = ListRuns<kRunPoints>;

/// Whether a layout's certified search may list its candidates (NearLists): point lists say
/// so (ListRuns::kListsCandidates); lattices and the band's blocks always stream.
template <typename Layout, typename = void>
struct lists_candidates : std::false_type {};
template <typename Layout>
struct lists_candidates<Layout, std::void_t<decltype(Layout::kListsCandidates)>> : std::bool_constant<Layout::kListsCandidates> {};

/// Loads thread t's points into a packet; lanes without points get best = -1, so they never
/// want a box or a triangle and never hold the warp back.
template <typename T, typename Layout>
__device__ SDF_INLINE int load_packet(const Layout& layout, int64_t t, int64_t& first, BvhPacket<T, Layout::kPoints>& pk) {
    const int count = layout.points_of(t, first);
    for (int k = 0; k < Layout::kPoints; ++k) {
        const Vec3<T> p(layout.position(first + (k < count ? k : 0)));
        pk.x[k] = p.x; pk.y[k] = p.y; pk.z[k] = p.z;
        pk.best_q[k] = count > 0 ? T(INFINITY) : T(-1);
        pk.radius[k] = pk.best_q[k];
        pk.best_slot[k] = -1;
        pk.best_triangle[k] = -1;
    }
    return count;
}

namespace detail {

/// nearest_first_walk()'s stack for a warp walking as one: the warp's entries in shared
/// memory, written by lane 0 and read by every lane after the warp has synchronised (the
/// walk's depth is warp-uniform). Entries without a key (NoKey) store only the node.
template <typename Key>
struct WarpStack {
    int32_t* node;
    Key* key;
    __device__ SDF_INLINE void store(int top, int32_t n, const Key& k) {
        if (threadIdx.x % 32 == 0) {
            node[top] = n;
            if constexpr (!std::is_empty_v<Key>) key[top] = k;
        }
    }
    __device__ SDF_INLINE Key key_at(int top) const {
        if constexpr (std::is_empty_v<Key>) return Key{};
        else return key[top];
    }
    __device__ SDF_INLINE int32_t node_at(int top) const { return node[top]; }
    __device__ SDF_INLINE void begin_pops() { __syncwarp(); }  // lane 0's pushes are seen
    __device__ SDF_INLINE void end_pops() { __syncwarp(); }    // read before lane 0 writes again
};

/// warp_search()'s query for nearest_first_walk(): a child is wanted when some lane of the
/// warp wants it (a vote), ordered and stacked by the warp's nearest point; after a scan the
/// warp agrees on its largest radius, below which a stacked subtree stays open.
template <typename T, int K, typename Near>
struct WarpNearestQuery {
    const BvhView<T>& bvh;
    BvhPacket<T, K>& pk;
    bool valid;
    Near& policy;
    T worst;  ///< the warp's largest radius: +inf, a seeded lane's, or a bounded search's bound
    bool scanned = false;
    T mine = T(-1);  ///< the thread's largest radius after a scan
    __device__ SDF_INLINE ChildOrder<T> measure(const BvhNode& n) {
        T d0, d1;
        const bool w0 = sdf::detail::child_wanted(n, 0, pk, d0), w1 = sdf::detail::child_wanted(n, 1, pk, d1);
        const bool want0 = __any_sync(kFullWarp, w0), want1 = __any_sync(kFullWarp, w1);
        const T m0 = warp_min(valid ? d0 : T(INFINITY)), m1 = warp_min(valid ? d1 : T(INFINITY));
        // keys: the warp's nearest point's distance, a bound for all
        return ChildOrder<T>::ordered(m1 < m0 ? 1 : 0, m0, m1, want0, want1);
    }
    __device__ SDF_INLINE bool enter(T) const { return true; }  // the votes decided
    __device__ SDF_INLINE void leaf(int32_t first, int32_t count) {
        mine = sdf::detail::scan_leaf_packet(bvh, first, count, pk, policy);
        scanned = true;
    }
    __device__ SDF_INLINE void node_done() {
        if (scanned) worst = warp_max(mine);
        scanned = false;
        mine = T(-1);
    }
    __device__ SDF_INLINE bool still_open(T key) const { return may_hold_nearer(key, worst); }
};

}  // namespace detail

/// The warp's shared traversal: completes the nearest triangle of every lane's points,
/// pruning with each lane's radius (`policy`: plain, or the streamed certificate's widened
/// one). `stack_node`/`stack_d2` are this warp's kBvhMaxDepth entries in shared memory.
template <typename T, int K, typename Near>
__device__ SDF_INLINE void warp_search(const BvhView<T>& bvh, BvhPacket<T, K>& pk, bool valid, int32_t* stack_node,
                                       T* stack_d2, Near& policy) {
    T worst = T(-1);  // the lanes' radii as they are (+inf, seeded, or a bounded search's bound)
    for (int k = 0; k < K; ++k) worst = max(worst, pk.radius[k]);
    detail::WarpNearestQuery<T, K, Near> q{bvh, pk, valid, policy, warp_max(valid ? worst : T(-1))};
    detail::WarpStack<T> stack{stack_node, stack_d2};
    nearest_first_walk<T>(bvh.nodes, q, stack);
}

/// The narrow band as the search sees it; width 0 = no band, skip_bricks false = every brick
/// searched (the finalize then applies the band).
struct BandSearch {
    double width = 0;
    MeshView<double> mesh{};  ///< for the side of a brick's centre (pseudonormal sign)
    bool winding_sign = false;
    /// The winding sign (each point's own), or the pseudonormal sign on a mesh that auto
    /// would sign that way (a solid: one side per ball that does not meet the surface). A
    /// pseudonormal sign forced on an open mesh can change sides away from the surface
    /// (beyond a rim), so there no brick is skipped.
    bool skip_bricks = false;
    /// How much farther than the true nearest the search's nearest may be, through slivers
    /// ranked by their edges (FloatSearchBound::sliver_reach_*): lowers the centre's bound.
    double sliver_reach = 0;
    /// The double search's tree (the same nodes and slots with the double constants), for a
    /// float search: a skipped brick takes the side at its centre's double-search triangle.
    BvhView<double> exact{};
};

/// The double search's triangle slot at p, seeded with a float search's `seed` slot: the
/// point queries' reference. Out of line: the warp kernels' registers stay their search's.
static __device__ __noinline__ int32_t double_search_slot(const BvhView<double>& exact, Vec3d p, int32_t seed) {
    return closest_triangle_bvh(exact, p, seed_hit(exact, seed, p)).slot;
}

/// The box of the warp's real points (uniform across the warp); lo > hi when it has none.
template <typename T, int K>
__device__ SDF_INLINE void warp_brick_box(const BvhPacket<T, K>& pk, int count, Vec3<T>& lo, Vec3<T>& hi) {
    const T inf = T(INFINITY);
    lo = Vec3<T>(inf, inf, inf);
    hi = Vec3<T>(-inf, -inf, -inf);
    for (int k = 0; k < count; ++k) {
        lo = Vec3<T>(min(lo.x, pk.x[k]), min(lo.y, pk.y[k]), min(lo.z, pk.z[k]));
        hi = Vec3<T>(max(hi.x, pk.x[k]), max(hi.y, pk.y[k]), max(hi.z, pk.z[k]));
    }
    lo = Vec3<T>(warp_min(lo.x), warp_min(lo.y), warp_min(lo.z));
    hi = Vec3<T>(warp_max(hi.x), warp_max(hi.y), warp_max(hi.z));
}

/// One batch's walk (every lane of the warp calls it): the warp's shared walk
/// (warp_search), for a seeded point list (ListRuns::seeded) after each lane's own descent.
template <typename T, typename Layout, typename Near>
__device__ SDF_INLINE void walk_batch(const BvhView<T>& bvh, const Layout& layout, BvhPacket<T, Layout::kPoints>& pk,
                                      int count, int32_t* stack_node, T* stack_d2, Near& policy) {
    if constexpr (lists_candidates<Layout>::value) {
        if (layout.seeded) seed_by_descent(bvh, pk, policy);
    }
    warp_search(bvh, pk, count > 0, stack_node, stack_d2, policy);
}

/// Narrow band: by 1-Lipschitz continuity every point p of the brick has |d(p)| >= |d(c)| -
/// |p - c| for the box's centre c; when that bound (less a rounding allowance relative to the
/// coordinates: the float search is exact relative to them) exceeds the band's width, the
/// whole brick lies outside the band. Returns its NearestOutsideBand code (the side of c
/// with the pseudonormal sign, as the brick does not cross the surface; "per point" with the
/// winding sign, whose side may change away from the surface), or 0 when the brick must be
/// searched. `seed` receives c's nearest triangle.
template <typename T, int K>
__device__ SDF_INLINE int brick_band_code(const BvhView<T>& bvh, const BvhPacket<T, K>& pk, int count, const Vec3<T>& c,
                                          const BvhHit<T>& seed, const BandSearch& band) {
    T r2 = T(0);
    for (int k = 0; k < count; ++k) {
        const T dx = pk.x[k] - c.x, dy = pk.y[k] - c.y, dz = pk.z[k] - c.z;
        r2 = max(r2, dx * dx + dy * dy + dz * dz);
    }
    r2 = warp_max(r2);
    const double scale = fmax(fmax(fabs(double(c.x)), fabs(double(c.y))), fabs(double(c.z)));
    const double dc = sqrt(double(seed.distance_squared)), r = sqrt(double(r2));
    const double slack = 64.0 * double(std::numeric_limits<T>::epsilon()) * (scale + dc + r) + 1e-300;
    if (!(dc - r - slack - band.sliver_reach > band.width)) return 0;
    if (band.winding_sign) return kOutsideBandSignPerPoint;
    // The side needs the double search's triangle (the points' own): a float near-tie may pick
    // a triangle whose pseudonormal puts c on the other side (a sliver's edge a float ulp
    // beside a sharp edge), and every point of the brick would carry that side.
    int32_t slot = seed.slot;
    if constexpr (std::is_same_v<T, float>) slot = double_search_slot(band.exact, Vec3d(c), seed.slot);
    const SignedDistanceSample<double> s = signed_distance_to_triangle(band.mesh, Vec3d(c), bvh.triangle_index[slot]);
    return s.distance < 0 ? kOutsideBandInside : kOutsideBandOutside;
}

/// Blocks per SM the fused warp kernel is compiled for: 4 caps it at 128 registers (146-154
/// uncapped), which measured 7-11% faster on an H100 (docs/gpu-notes.md).
constexpr int kFusedMinBlocks = 4;

/// Blocks per SM the listed form of a `Layout` is compiled for: with one point a thread
/// (lists below some 4M points, taken by resident warps) 8, at 64 registers: 1M points
/// 3.01 -> 2.93 ms near the surface, 2.85 -> 2.74 ms uniform on an H200 (7: 2.98, 2.81);
/// with two 6, at 80 registers with 200-400 bytes of spills: 1M points 4.50 -> 4.22 ms near
/// the surface, 4.38 -> 3.93 ms uniform (before the resident warps); with four (16.8M
/// points) kFusedMinBlocks, where 6 took 29.5 -> 32.1 ms (docs/gpu-notes.md).
template <typename Layout>
constexpr int listed_min_blocks() {
    return Layout::kPoints == 1 ? 8 : Layout::kPoints == 2 ? 6 : kFusedMinBlocks;
}

/// Lane k's exact point (a run's lanes beyond its count repeat its first point, as in
/// load_packet), for the streamed certificate's double evaluations.
template <typename Layout>
struct RunPoint {
    Layout layout;
    int64_t first = 0;
    int count = 0;
    SDF_CPU_GPU SDF_INLINE Vec3d operator()(int k) const { return layout.position(first + (k < count ? k : 0)); }
};

template <typename Layout>
using StreamedRun = StreamedCertifiedNear<float, Layout::kPoints, RunPoint<Layout>>;
template <typename Layout>
using ListedRun = ListedCertifiedNear<float, Layout::kPoints, RunPoint<Layout>>;

/// Writes the nearest triangle of the thread's `count` points: the plain search's, or with
/// the certificate fused (kCertified, float only) the double search's, counting the points
/// and those that needed double evaluations (every lane of the warp must call this); with
/// the listed certificate the float winner, which rerank_near_lists() replaces and counts.
template <bool kCertified, bool kListed = false, typename T, int K, typename Near>
__device__ SDF_INLINE void write_nearest(const BvhView<T>& bvh, const BvhPacket<T, K>& pk, Near& policy, int64_t first,
                                         int count, const StreamedCertify& cert, int* nearest) {
    if constexpr (kListed) {
#pragma unroll
        for (int k = 0; k < K; ++k) {
            bool unused = false;
            const int32_t winner = policy.finish(bvh, k, pk, unused);
            if (k < count) nearest[first + k] = winner;
        }
    } else if constexpr (kCertified) {
        unsigned reranked = 0, found = 0;
#pragma unroll
        for (int k = 0; k < K; ++k) {
            if (k >= count) continue;
            bool r = false;
            nearest[first + k] = policy.finish(bvh, k, pk, r);
            reranked += unsigned(r);
            ++found;
        }
        warp_add(cert.counters + 0, found);
        warp_add(cert.counters + 1, reranked);
    } else {
        for (int k = 0; k < count; ++k)
            nearest[first + k] = bvh.triangle_index[pk.best_slot[k]];
    }
}

/// Where each warp of a search takes its batches of 32 threads from: without a counter the
/// grid's warps take one batch each (warp w, batch w); with one, a grid of resident warps
/// takes batch after batch from it (persistent threads, Aila & Laine 2009), so a warp whose
/// batch ends early does not idle until the slowest warp of its block ends.
struct WarpBatches {
    unsigned long long* next = nullptr;  ///< the next batch to take, zeroed before the launch
    int64_t count = 0;                   ///< batches: the layout's threads / 32, rounded up

    /// The grid's warp `grid_warp`'s first batch (`first`) or its next (every lane calls
    /// it): `count` or more when none is left.
    __device__ SDF_INLINE int64_t take(int64_t grid_warp, bool first) const {
        if (next == nullptr) return first ? grid_warp : count;
        unsigned long long b = 0;
        if (threadIdx.x % 32 == 0) b = atomicAdd(next, 1ull);
        return int64_t(__shfl_sync(kFullWarp, b, 0));
    }
};

/// One batch of the warp search (thread t of the layout in this lane); kCertified (float
/// only) fuses the certified search (kernels/bvh/streamed_certificate.h), so `nearest`
/// receives the double search's triangles without the separate certify pass; kListed leaves
/// each point's candidates in `lists` for rerank_near_lists() instead of streaming them in
/// double.
template <typename T, typename Layout, bool kCertified, bool kListed>
__device__ SDF_INLINE void warp_search_batch(const BvhView<T>& bvh, const Layout& layout, const BandSearch& band,
                                             const StreamedCertify& cert, int* nearest, const NearLists& lists, int64_t t,
                                             int32_t* stack_node, T* stack_d2) {
    int64_t first = 0;
    BvhPacket<T, Layout::kPoints> pk;
    const int count = load_packet<T>(layout, t, first, pk);
    if (band.width > 0 && band.skip_bricks) {
        Vec3<T> lo, hi;
        warp_brick_box(pk, count, lo, hi);
        if (!(lo.x <= hi.x)) return;  // no point in this warp
        const Vec3<T> c((lo.x + hi.x) / T(2), (lo.y + hi.y) / T(2), (lo.z + hi.z) / T(2));
        const int code = brick_band_code(bvh, pk, count, c, closest_triangle_bvh(bvh, c), band);
        if (code != 0) {
            for (int k = 0; k < count; ++k) nearest[first + k] = code;
            return;
        }
    }
    if constexpr (kListed) {
        ListedRun<Layout> policy(cert.slack, RunPoint<Layout>{layout, first, count}, lists, first, count);
        walk_batch(bvh, layout, pk, count, stack_node, stack_d2, policy);
        write_nearest<true, true>(bvh, pk, policy, first, count, cert, nearest);
    } else if constexpr (kCertified) {
        StreamedRun<Layout> policy(cert.slack, cert.exact, RunPoint<Layout>{layout, first, count});
        walk_batch(bvh, layout, pk, count, stack_node, stack_d2, policy);
        write_nearest<true>(bvh, pk, policy, first, count, cert, nearest);
    } else {
        PacketPlainNear policy;
        walk_batch(bvh, layout, pk, count, stack_node, stack_d2, policy);
        write_nearest<false>(bvh, pk, policy, first, count, cert, nearest);
    }
}

/// The warp search of a lattice slab or a sorted point list, batch by batch (WarpBatches).
template <typename T, typename Layout, bool kCertified, bool kListed = false, int kMinBlocks = kCertified ? kFusedMinBlocks : 1>
__global__ void __launch_bounds__(kBvhThreads, kMinBlocks)
    nearest_triangle_bvh_warp(BvhView<T> bvh, Layout layout, BandSearch band, StreamedCertify cert, int* nearest,
                              NearLists lists, WarpBatches batches) {
    constexpr int kWarps = kBvhThreads / 32;
    __shared__ int32_t stack_node[kWarps][kBvhMaxDepth];
    __shared__ T stack_d2[kWarps][kBvhMaxDepth];
    const int w = threadIdx.x / 32;
    const int64_t grid_warp = (int64_t(blockIdx.x) * blockDim.x + threadIdx.x) / 32;
    // Every lane stays to the end of each batch: the votes and shuffles need the whole warp.
    for (int64_t b = batches.take(grid_warp, true); b < batches.count; b = batches.take(grid_warp, false))
        warp_search_batch<T, Layout, kCertified, kListed>(bvh, layout, band, cert, nearest, lists,
                                                          b * 32 + threadIdx.x % 32, stack_node[w], stack_d2[w]);
}

/// The grid of a warp search over `layout`: one warp a batch, or with `queue` (a device
/// counter) only the warps the GPU holds at once, taking batches from it.
template <typename Kernel, typename Layout>
std::pair<int, WarpBatches> warp_grid(Kernel kernel, const Layout& layout, unsigned long long* queue) {
    WarpBatches batches{nullptr, (layout.threads() + 31) / 32};
    int blocks = blocks_for(layout.threads(), kBvhThreads);
    if (queue != nullptr) {
        int device = 0, sms = 1, per_sm = 1;
        CUDA_CHECK(cudaGetDevice(&device));
        CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
        CUDA_CHECK(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, kBvhThreads, 0));
        if (int64_t(blocks) > int64_t(sms) * per_sm) {  // fewer: one batch each, no counter
            blocks = sms * std::max(per_sm, 1);
            CUDA_CHECK(cudaMemsetAsync(queue, 0, sizeof *queue));
            batches.next = queue;
        }
    }
    return {blocks, batches};
}

/// Launches the warp search, with the certificate fused when `cert` holds one (float): its
/// candidates listed in `lists` where given (rerank_near_lists() then finishes it),
/// otherwise streamed. `queue` (a device counter, or null): resident warps take the
/// batches from it (WarpBatches).
template <typename T, typename Layout>
void launch_bvh_warp(const BvhView<T>& bvh, const Layout& layout, const BandSearch& band, const StreamedCertify& cert,
                     int* nearest, const NearLists& lists = {}, unsigned long long* queue = nullptr) {
    const auto launch = [&](auto kernel) {
        const auto [blocks, batches] = warp_grid(kernel, layout, queue);
        kernel<<<blocks, kBvhThreads>>>(bvh, layout, band, cert, nearest, lists, batches);
    };
    if constexpr (std::is_same_v<T, float>) {
        if constexpr (lists_candidates<Layout>::value) {
            if (cert.exact && lists.enabled()) {
                if constexpr (Layout::kPoints == 1) {
                    // SDF_LIST_MIN_BLOCKS=6: one point a lane at 6 blocks an SM, as before, for
                    // measurement.
                    static const bool six = [] {
                        const char* e = std::getenv("SDF_LIST_MIN_BLOCKS");
                        return e != nullptr && std::atoi(e) == 6;
                    }();
                    if (six) return launch(nearest_triangle_bvh_warp<T, Layout, true, true, 6>);
                }
                launch(nearest_triangle_bvh_warp<T, Layout, true, true, listed_min_blocks<Layout>()>);
                return;
            }
        }
        if (cert.exact) {
            launch(nearest_triangle_bvh_warp<T, Layout, true>);
            return;
        }
    }
    launch(nearest_triangle_bvh_warp<T, Layout, false>);
}

}  // namespace sdf::cuda
