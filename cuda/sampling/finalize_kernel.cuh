/// @file finalize_kernel.cuh
/// @brief After the nearest-triangle search: Eberly's closest point on the winning triangle,
/// the pseudonormal sign and the exact gradient (thesis sections 3.3-3.4), on the GPU, with
/// the same signed_distance_to_triangle() the CPU reference calls. As on the CPU, this step
/// runs in double at the exact lattice position whatever the search precision: it costs one
/// triangle per point and makes float fields exact to double rounding. In sign mode
/// "winding" the sample then takes the fast winding number's side (winding_sign_kernel.cuh).
#pragma once

#include <cstdlib>

#include "core/sampling/sampled_field.h"
#include "cuda/sampling/point_pieces.h"
#include "cuda/sampling/winding_sign_kernel.cuh"
#include "kernels/distance/signed_distance.h"

namespace sdf::cuda {

/// What `nearest` holds for a point of a brick wholly outside the band (set by
/// the search, bvh_candidates_kernel.cuh).
enum NearestOutsideBand : int {
    kOutsideBandOutside = -2,        ///< positive side
    kOutsideBandInside = -3,         ///< negative side
    kOutsideBandSignPerPoint = -4,   ///< the winding number decides, point by point
    /// No triangle within the sweep's bound: outside the band, its side taken from its
    /// neighbours after finalize, which leaves its outputs to that pass (the sparse band's
    /// finish_band_blocks, cuda/bvh/bvh_band_blocks.cu). INT_MAX: what the sweep's atomicMin
    /// over the triangle indices starts from, so a point no triangle reaches keeps it.
    kOutsideBandFlood = 0x7fffffff,
};

/// Per-piece results, downloaded and scattered into the field by the host.
struct PieceOutputs {
    double* distance;
    Vec3d* gradient;        ///< null: not wanted (a sparse band without its gradient channel)
    int* triangle;
    int64_t* output_index;  ///< -1: padding or discarded; null: not wanted (a sparse band's block-major arrays)
};

/// Writes sample i, or the band's value when it lies outside a narrow band (width > 0).
__device__ inline void store_sample(const PieceOutputs& out, int64_t i, const SignedDistanceSample<double>& s, double band_width) {
    if (band_width > 0 && fabs(s.distance) > band_width) {
        out.distance[i] = s.distance < 0 ? -band_width : band_width;
        if (out.gradient) out.gradient[i] = Vec3d(0.0);
        out.triangle[i] = kOutsideBandTriangle;
        return;
    }
    out.distance[i] = s.distance;
    if (out.gradient) out.gradient[i] = s.gradient;
    out.triangle[i] = s.triangle;
}

/// Per point of a listed search, what the re-rank (rerank_near_lists(),
/// certify_kernel.cuh) did with its side: decided from the search's candidates and the
/// sample stored, or left to the finalize.
enum NearestSide : int8_t { kNearestSideOpen = 0, kNearestSideStored = 1 };

/// The block size of every finalize launch (launch_finalize_samples), which __launch_bounds__ needs.
constexpr int kFinalizeBlock = 256;

/// Blocks per SM that the warp winding walk's registers must allow. The walk is latency-bound
/// (dependent double operations); at its natural 95 registers only 2 blocks fit an SM (25%
/// occupancy). Capped at 64 registers (4 blocks) the dragon's 16.8M points near the surface
/// took 52.7 ms instead of 65.5 ms on an H200 (80 registers: 55.7; the walk's stack in shared
/// memory, 40-95 registers: 54.7-68.3 ms). docs/gpu-notes.md.
constexpr int kWarpWindingMinBlocks = 4;

/// With `Winding` the sample then takes the winding number's side; without it the kernel has
/// no winding code at all (pseudonormal mode: the kernel as it was before sign modes).
/// With a narrow band (band_width > 0, SamplerOptions::band_width) a sample with |d| > w
/// becomes the band's value with its sign, gradient 0 and kOutsideBandTriangle; `nearest`
/// may then also hold the search's outside-band codes (bvh_candidates_kernel.cuh), whose
/// points get the same values without a triangle.
/// The winding sides are found per warp (warp_winding_inside: every thread of the block,
/// in the piece or not, reaches that call; blocks are whole warps), or with `PerThread` by
/// each thread alone (the same bits: the measurement baseline, SDF_CUDA_WINDING_PER_THREAD).
template <typename Piece, bool Winding, bool PerThread = false, int MinBlocks = (Winding && !PerThread ? kWarpWindingMinBlocks : 1)>
__global__ void __launch_bounds__(kFinalizeBlock, MinBlocks)
    finalize_samples(MeshView<double> mesh, Piece piece, const int* nearest, WindingSignView sign, double band_width,
                     PieceOutputs out, const int8_t* nearest_sides) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    const bool in_piece = i < piece.size();
    const int64_t o = !in_piece || piece.block_local(i) < 0 ? -1 : piece.output_index(i);
    if (in_piece && out.output_index) out.output_index[i] = o;
    const int n_read = o >= 0 ? nearest[i] : -1;
    const bool flood = n_read == kOutsideBandFlood;
    const int n = flood ? -1 : n_read;  // a triangle where >= 0
    // The re-rank stored the sample where the search's candidates decided its side
    // (`nearest_sides`, rerank_near_lists(), which counted it): nothing is left to do.
    const bool stored = Winding && nearest_sides != nullptr && n >= 0 && nearest_sides[i] == kNearestSideStored;
    const Vec3d p = o >= 0 && !stored && (n >= 0 || Winding) ? piece.position(i) : Vec3d(0.0);
    SignedDistanceSample<double> s;
    if (n >= 0 && !stored) s = signed_distance_to_triangle(mesh, p, n);
    bool winding_inside = false;
    if constexpr (Winding) {
        // The closest triangle's side where the mesh's table vouches for it (surface_side.h).
        const bool by_surface = !stored && n >= 0 && sign.certify &&
                                surface_side(sign.surface, sign.view, p, n, s.distance, winding_inside);
        const bool wants = o >= 0 && !stored && !by_surface && (n >= 0 || n == kOutsideBandSignPerPoint);
        if constexpr (PerThread) {
            if (by_surface) count_winding_stage(sign, WindingStage::Surface);
            if (wants) {
                const WindingSide side = winding_side(sign, p);
                count_winding_stage(sign, side.stage);
                winding_inside = side.inside;
            }
        } else {
            winding_inside = warp_winding_inside(sign, p, wants, by_surface, winding_inside);
        }
    }
    if (o < 0 || flood || stored) return;
    if (n >= 0) {
        if constexpr (Winding) s = with_sign(s, winding_inside);  // apply_winding_sign()'s side
        store_sample(out, i, s, band_width);
        return;
    }
    bool inside = n == kOutsideBandInside;  // a brick wholly outside the band
    if constexpr (Winding) {
        if (n == kOutsideBandSignPerPoint) inside = winding_inside;
    }
    out.distance[i] = inside ? -band_width : band_width;
    if (out.gradient) out.gradient[i] = Vec3d(0.0);
    out.triangle[i] = kOutsideBandTriangle;
}

/// Whether the environment asks for the per-thread winding traversal (SDF_CUDA_WINDING_PER_THREAD
/// set: the baseline that docs/gpu-notes.md measures the warp traversal against).
inline bool winding_per_thread() {
    static const bool per_thread = std::getenv("SDF_CUDA_WINDING_PER_THREAD") != nullptr;
    return per_thread;
}

/// Launches finalize_samples with or without the winding sign, as `sign` says, over the
/// piece's `count` points in blocks of kFinalizeBlock; `nearest_sides` (or null): what
/// rerank_near_lists() did with each point's side (NearestSide). Without it, compiled for
/// `PlainMinBlocks` blocks per SM: the sparse band asks for 4 (64 registers where it takes 100
/// uncapped, 2 blocks): its finalize is latency-bound, and ran 1.8x faster so on an H200
/// (docs/large-lattices.md); the other callers keep the uncapped kernel, not measured so.
template <int PlainMinBlocks = 1, typename Piece>
void launch_finalize_samples(int64_t count, MeshView<double> mesh, const Piece& piece, const int* nearest,
                             const WindingSignView& sign, double band_width, PieceOutputs out, const int8_t* nearest_sides = nullptr) {
    const int blocks = int((count + kFinalizeBlock - 1) / kFinalizeBlock), threads = kFinalizeBlock;
    if (!sign.enabled())
        finalize_samples<Piece, false, false, PlainMinBlocks><<<blocks, threads>>>(mesh, piece, nearest, sign, band_width, out, nearest_sides);
    else if (winding_per_thread())
        finalize_samples<Piece, true, true><<<blocks, threads>>>(mesh, piece, nearest, sign, band_width, out, nearest_sides);
    else finalize_samples<Piece, true><<<blocks, threads>>>(mesh, piece, nearest, sign, band_width, out, nearest_sides);
}

}  // namespace sdf::cuda
