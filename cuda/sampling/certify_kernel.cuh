/// @file certify_kernel.cuh
/// @brief The certified float search on the GPU (kernels/distance/search_certificate.h).
/// The warp kernel fuses it into its traversal (StreamedCertify below,
/// kernels/bvh/streamed_certificate.h). The other float searches (candidates and per-thread
/// BVH kernels, tuned brute force) run the separate pass here, between the float search and
/// finalize_samples(): every point's float winner seeds a
/// certified BVH search (pruning radius widened by the float error bound, candidates kept),
/// and the candidates are re-ranked in double, so `nearest` ends up holding the double
/// search's triangle. One seeded traversal per point: the radius is already the winner's, so
/// it visits only the leaves around the point.
///
/// More than kNearCandidates candidates: the search runs again keeping
/// kWideCandidates; more than that (a fan of that many triangles within the bound), the
/// double BVH search seeded with the winner decides (closest_triangle_bvh.h), which is the
/// double brute force up to the rounding of its box distances (8 ulps in double).
#pragma once

#include <cstdlib>
#include <vector>

#include "core/bvh/triangle_bvh.h"
#include "core/sampling/certified_search.h"
#include "cuda/util/cuda_check.h"
#include "cuda/util/device_buffer.h"
#include "cuda/sampling/finalize_kernel.cuh"
#include "cuda/sampling/launch_util.cuh"
#include "kernels/bvh/closest_triangle_bvh.h"
#include "kernels/bvh/streamed_certificate.h"
#include "kernels/distance/signed_distance.h"
#include "kernels/winding/surface_side.h"

namespace sdf::cuda {

constexpr int kWideCandidates = 64;

/// The float and double BVH (same nodes, same slots), the slot of each prepared-mesh
/// triangle, the bound and three counters: points, re-ranked, full double search.
struct CertifyView {
    BvhView<float> bvh;
    BvhView<double> exact;
    const int32_t* slot_of = nullptr;
    SearchSlack<float> slack;
    unsigned long long* counters = nullptr;
};

/// The certificate fused into a warp search (kernels/bvh/streamed_certificate.h): the double
/// triangles in BVH order, the slack at the launch's points and the counters (points,
/// re-ranked, full double) of the DeviceCertifier. exact == nullptr: not fused (a double
/// search, or a bound too loose to certify: the separate pass below runs instead).
struct StreamedCertify {
    const PackedTriangle<double>* exact = nullptr;
    SearchSlack<float> slack;
    unsigned long long* counters = nullptr;
};

/// Adds `value` over the whole warp (every lane must take part) with one atomic.
__device__ inline void warp_add(unsigned long long* counter, unsigned value) {
    for (int o = 16; o > 0; o >>= 1) value += __shfl_xor_sync(0xffffffffu, value, o);
    if ((threadIdx.x % 32) == 0 && value != 0) atomicAdd(counter, (unsigned long long)value);
}

/// Adds `flag` over the active threads of the warp with one atomic.
__device__ inline void warp_count(unsigned long long* counter, bool flag) {
    const unsigned active = __activemask();
    const unsigned votes = __ballot_sync(active, flag);
    if ((threadIdx.x % 32) == unsigned(__ffs(active) - 1) && votes != 0) atomicAdd(counter, (unsigned long long)__popc(votes));
}

/// A certified float search at p seeded with `seed`, keeping N candidates, re-ranked in
/// double (r.overflow: more than N within the bound); `hit` receives the float winner.
template <int N>
__device__ inline Rerank certified_candidates(const CertifyView& v, const Vec3d& p, const BvhHit<float>& seed, BvhHit<float>& hit) {
    const Vec3f pt(p);
    NoBvhStats none;
    CertifiedNear<float, N> near{v.slack, {}};
    hit = closest_triangle_bvh(v.bvh, pt, seed, none, near);
    auto index_of = [&](int32_t s) { return v.bvh.triangle_index[s]; };
    return rerank_in_double(v.exact.packed, index_of, p.x, p.y, p.z, hit.slot, v.slack.radius(hit.distance_squared), near.near);
}

/// The double search's triangle at p from `seed` (a float winner's hit) where more than
/// kNearCandidates lie within the bound: kWideCandidates kept, and beyond that the double
/// search seeded with it.
__device__ inline int32_t wide_certified_slot(const CertifyView& v, const Vec3d& p, const BvhHit<float>& seed) {
    BvhHit<float> hit;
    const Rerank r = certified_candidates<kWideCandidates>(v, p, seed, hit);
    return r.overflow ? closest_triangle_bvh(v.exact, p, seed_hit(v.exact, seed.slot, p)).slot : r.slot;
}

/// The double search's triangle at p from a float winner `triangle` (prepared-mesh index):
/// a certified float search seeded with it, keeping kNearCandidates and then, where more
/// lie within the bound, kWideCandidates; beyond that the double search seeded with it.
/// `reranked`: double evaluations were needed; `full`: more than kNearCandidates.
__device__ inline int32_t certified_triangle(const CertifyView& v, const Vec3d& p, int32_t triangle, bool& reranked, bool& full) {
    const Vec3f pt(p);
    const BvhHit<float> seed = seed_hit(v.bvh, v.slot_of[triangle], pt);
    BvhHit<float> hit;
    Rerank r = certified_candidates<kNearCandidates>(v, p, seed, hit);
    full = r.overflow;
    if (r.overflow) {
        r.slot = wide_certified_slot(v, p, hit);
        r.reranked = true;
    }
    reranked = r.reranked;
    return v.bvh.triangle_index[r.slot];
}

/// The double search's triangle at p for an overflowed list (more than its slots within the
/// bound): the wide search at once. Out of line: its candidate arrays and walks are for
/// the 0.4-0.9% of lists that overflow, not for every point's path.
static __device__ __noinline__ int32_t overflowed_list_triangle(const CertifyView& v, Vec3d p, int32_t triangle) {
    return v.bvh.triangle_index[wide_certified_slot(v, p, seed_hit(v.bvh, v.slot_of[triangle], Vec3f(p)))];
}

/// At most 72 registers (seven blocks of 128 threads an SM): ptxas chose 78 for the three
/// walks below, one block fewer, where 72 costs 16 bytes of spills.
template <typename Piece>
__global__ void __launch_bounds__(128, 7) certify_nearest(CertifyView v, Piece piece, int* nearest) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= piece.size()) return;
    const int n = nearest[i];
    if (n < 0) return;  // outside the band: no triangle
    bool reranked = false, full = false;
    nearest[i] = certified_triangle(v, piece.position(i), n, reranked, full);
    warp_count(v.counters + 0, true);
    warp_count(v.counters + 1, reranked);
    warp_count(v.counters + 2, full);
}

/// What nearest_side() needs beside a point's candidates (the mesh, the certified winding
/// sign's table and tree), and where a decided point's sample goes: `side` receives per
/// point with a triangle kNearestSideStored (decided, its sample stored in `out` as
/// finalize_samples() would, with `band_width`, and counted in `nearest_count`) or
/// kNearestSideOpen (the finalize decides); points without one (outside the band) are not
/// written, nor read. Null: not asked (no table, another sign).
struct NearestSideInputs {
    MeshView<double> mesh{};
    SurfaceSideView surface{};
    WindingView<double> winding{};
    int8_t* side = nullptr;
    PieceOutputs out{};
    double band_width = 0;
    unsigned long long* nearest_count = nullptr;  ///< the winding sign's WindingStage::Nearest counter, or null
};

/// The listed certificate's second half (kernels/bvh/streamed_certificate.h): every point's
/// float winner `nearest` replaced by the double search's triangle from its list, and, where
/// asked, the point's side from those candidates alone (nearest_side(), surface_side.h) and
/// then its sample, which saves the finalize its walk and its closest point. One thread per
/// point, no walk but an overflowed list's double search (an overflowed list takes
/// certify_nearest's seeded search); apart from the finalize, whose registers are capped for
/// its winding walk.
template <typename Piece, int kMinBlocks = 1>
__global__ void __launch_bounds__(128, kMinBlocks)
    rerank_near_lists(CertifyView v, Piece piece, NearLists lists, int* nearest, NearestSideInputs sides) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= piece.size()) return;
    const int n = nearest[i];
    if (n < 0) return;  // outside the band: no triangle
    const Vec3d p = piece.position(i);
    bool reranked = false, overflow = false;
    const auto full_search = [&](const Vec3d& x) { return overflowed_list_triangle(v, x, n); };
    const int32_t t = rerank_near_list(lists, i, v.slack, v.exact.packed, v.bvh.triangle_index, p, n, full_search, reranked, overflow);
    nearest[i] = t;
    if (sides.side != nullptr) {
        bool stored = false;
        const int32_t count = lists.count[i];
        if (count > 0) {
            const SignedDistanceSample<double> s = signed_distance_to_triangle(sides.mesh, p, t);
            const NearTriangles near{lists.slot + i, count, beyond_candidates_squared(v.slack, lists.best_q[i]), lists.rows};
            bool inside = false;
            stored = nearest_side(sides.surface, sides.winding, p, t, s.distance, s.closest_point, near, inside);
            if (stored) store_sample(sides.out, i, with_sign(s, inside), sides.band_width);
        }
        sides.side[i] = stored ? kNearestSideStored : kNearestSideOpen;
        if (sides.nearest_count != nullptr) warp_count(sides.nearest_count, stored);
    }
    warp_count(v.counters + 0, true);
    warp_count(v.counters + 1, reranked);
    warp_count(v.counters + 2, overflow);
}

/// Host side: the float BVH, the double constants in BVH order, the slot of every triangle
/// and the counters on the device, for certify_nearest() after a float search (the BVH
/// sampler's and the tuned brute force's).
class DeviceCertifier {
public:
    DeviceCertifier(const TriangleBvh& bvh, const PreparedMesh& mesh) : bound_(float_search_bound(mesh)) {
        nodes_.upload(bvh.nodes);
        packed_.upload(bvh.packed_float);
        exact_.upload(bvh.packed_double);
        triangle_index_.upload(bvh.triangle_index);
        std::vector<int32_t> slots(bvh.triangle_index.size());
        for (size_t s = 0; s < slots.size(); ++s) slots[size_t(bvh.triangle_index[s])] = int32_t(s);
        slot_of_.upload(slots);
        counters_.allocate(3);
        reset();
        arrays_ = {nodes_.get(), packed_.get(), exact_.get(), triangle_index_.get(), slot_of_.get()};
        num_nodes_ = int(bvh.nodes.size());
        num_triangles_ = int(bvh.triangle_index.size());
    }

    /// Over a BVH already on the device (the GPU build's, with its bound): nothing is
    /// copied; the arrays must outlive the certifier.
    DeviceCertifier(const BvhView<float>& bvh, const PackedTriangle<double>* exact, const int32_t* slot_of,
                    const FloatSearchBound& bound)
        : bound_(bound) {
        counters_.allocate(3);
        reset();
        arrays_ = {bvh.nodes, bvh.packed, exact, bvh.triangle_index, slot_of};
        num_nodes_ = bvh.num_nodes;
        num_triangles_ = bvh.num_triangles;
    }

    /// Replaces `nearest` (prepared-mesh triangles of the float search, or band codes) with
    /// the double search's triangles, for points of largest |coordinate| `point_coordinate`.
    template <typename Piece>
    void certify(const Piece& piece, double point_coordinate, int* nearest) const {
        const int64_t n = piece.size();
        if (n == 0) return;
        certify_nearest<<<blocks_for(n, 128), 128>>>(view(point_coordinate), piece, nearest);
        CUDA_CHECK_LAUNCH("certify_nearest");
    }

    /// Replaces `nearest` (the float winners of a listed warp search, streamed(point_coordinate)
    /// its certificate) with the double search's triangles from `lists`, and finds the sides
    /// `sides` asks for.
    template <typename Piece>
    void rerank_lists(const Piece& piece, double point_coordinate, const NearLists& lists, int* nearest,
                      const NearestSideInputs& sides) const {
        const int64_t n = piece.size();
        if (n == 0) return;
        // Capped at 80 registers (6 blocks an SM; 96 uncapped, since it stores the samples it
        // decides): 1M points near the surface 3.01 -> 2.94 ms, 16.8M 19.5 -> 18.4 ms on an
        // H200 (8 blocks: 3.00, 18.3 ms; docs/gpu-notes.md). SDF_RERANK_MIN_BLOCKS=1 or 8
        // compiles it so, for measurement.
        static const int forced = [] {
            const char* e = std::getenv("SDF_RERANK_MIN_BLOCKS");
            return e ? std::atoi(e) : 0;
        }();
        const int blocks = blocks_for(n, 128);
        if (forced == 1) rerank_near_lists<Piece, 1><<<blocks, 128>>>(view(point_coordinate), piece, lists, nearest, sides);
        else if (forced == 8) rerank_near_lists<Piece, 8><<<blocks, 128>>>(view(point_coordinate), piece, lists, nearest, sides);
        else rerank_near_lists<Piece, 6><<<blocks, 128>>>(view(point_coordinate), piece, lists, nearest, sides);
        CUDA_CHECK_LAUNCH("rerank_near_lists");
    }

    /// The fused certificate for points of largest |coordinate| `point_coordinate`; not
    /// fused (exact == nullptr) when the bound cannot certify there.
    StreamedCertify streamed(double point_coordinate) const {
        StreamedCertify c;
        c.slack = make_search_slack(bound_, point_coordinate);
        if (!c.slack.certify) return c;
        c.exact = arrays_.exact;  // this certifier's upload, or the GPU build's arrays
        c.counters = counters_.get();
        return c;
    }

    void reset() { CUDA_CHECK(cudaMemset(counters_.get(), 0, 3 * sizeof(unsigned long long))); }

    /// The counts since reset().
    void read(CertificateCounters& c) const {
        unsigned long long h[3] = {0, 0, 0};
        counters_.download(h, 3);
        CUDA_CHECK(cudaStreamSynchronize(0));
        c.points = int64_t(h[0]);
        c.reranked = int64_t(h[1]);
        c.full_double = int64_t(h[2]);
    }

private:
    CertifyView view(double point_coordinate) const {
        CertifyView v;
        v.bvh = {arrays_.nodes, arrays_.packed, arrays_.triangle_index, num_nodes_, num_triangles_};
        v.exact = {arrays_.nodes, arrays_.exact, arrays_.triangle_index, num_nodes_, num_triangles_};
        v.exact.margin = double_prune_margin(bound_);  // the full double search equals the brute force
        v.slot_of = arrays_.slot_of;
        v.slack = make_search_slack(bound_, point_coordinate);
        v.counters = counters_.get();
        return v;
    }

    /// The arrays the kernel reads: the buffers below, or another owner's.
    struct Arrays {
        const BvhNode* nodes = nullptr;
        const PackedTriangle<float>* packed = nullptr;
        const PackedTriangle<double>* exact = nullptr;
        const int32_t* triangle_index = nullptr;
        const int32_t* slot_of = nullptr;
    };

    FloatSearchBound bound_;
    Arrays arrays_;
    DeviceBuffer<BvhNode> nodes_;
    DeviceBuffer<PackedTriangle<float>> packed_;
    DeviceBuffer<PackedTriangle<double>> exact_;
    DeviceBuffer<int32_t> triangle_index_, slot_of_;
    DeviceBuffer<unsigned long long> counters_;
    int num_nodes_ = 0, num_triangles_ = 0;
};

}  // namespace sdf::cuda
