/// @file sparse_band_sampler.h
/// @brief The sparse narrow band (issue 35): a SparseBandField sampled with work that grows
/// with the band, not with the lattice, by any bound sampler's certified point kernel.
///
/// 1. Active blocks: every triangle's box, dilated by W (and a margin of 1e-4 spacings that
///    covers the rounding of the cells' bounds and of the band test's distance), rasterised
///    into the blocks whose cells it meets (a bit per block). A point with |d| <= W lies in
///    such a block; a block outside it has no triangle in its cell.
/// 2. Their lattice points: through the backend's block kernel where it has one (the CPU
///    BVH: its dense brick kernel with the band's brick skip, block by block; the CUDA BVH:
///    its warp or candidates kernel over the blocks in device memory), else, in batches,
///    through BoundSampler::query: the certified search, the sign rule and the evaluation of
///    the dense path at the same positions (Lattice::position_of_coords), then the band's
///    rule of narrow_band.h.
/// 3. The outside, cell by cell of an octree over the inactive blocks: a cell that meets no
///    triangle and whose side is proven uniform is one sign, queried at one lattice point of
///    the cell with the dense rule; a single block that is not proven uniform is queried at
///    every point (a mixed block, or a tile when its sides agree). Uniform means:
///    - pseudonormal sign of a solid (choose_sign_mode's conditions): always (a cell without
///      surface lies on one side);
///    - winding sign, no boundary edges (every edge's oriented uses cancel): always (w is an
///      integer off the surface);
///    - winding sign with boundary edges: |w~(c) - 1/2| > e(c) + G delta at the cell's centre c
///      (w~ the fast winding number with its certified bound e: truncation and rounding,
///      certified_winding.h; delta the half diagonal) with the
///      Biot-Savart bound G = (1/4 pi) sum_e m_e len_e / (dist(c, e) - delta)^2 over the
///      boundary edges e (net oriented uses m_e) of |grad w| in the cell;
///    - pseudonormal sign of any other mesh: never (every inactive point is queried: the
///      dense path's cost, sparse memory).
///    The dense path's certified winding sign is the exact side of w at each point, and the
///    test above proves w stays on one side of 1/2 over the cell, so the cell's one side is
///    every point's (the tests check every point as well). With certification switched off
///    the dense sign is the fast value's side, which may differ where |w - 1/2| is within the
///    fast value's error: only the tests check that case.
#pragma once

#include <cstdint>
#include <functional>

#include "core/sampling/sampled_field.h"
#include "core/sampling/sparse_band.h"

namespace sdf {

class BoundSampler;

struct SparseBandPlan {
    Precision precision = Precision::Float;  ///< recorded in the field (the sampler's own)
    int threads = 0;                         ///< for the host steps (0: every core)
    int64_t batch_points = int64_t(1) << 20; ///< lattice points per query call
    BandChannels channels;                   ///< what the band holds (sparse_band.h): gradient, triangle when asked
};

/// A backend's block kernel: writes the values of the active blocks [first, last) of `band`
/// (band.active) as its dense lattice kernel with the band of band.width fills those points:
/// every lattice point's, in every channel the band holds (band.channels; without the
/// gradient or the closest_triangle channel that array is empty), into arrays allocated but
/// not written, whose padding the caller has written (+W, gradient 0, kOutsideBandTriangle;
/// a kernel may write it again with those values); and every block's band_mask (allocated,
/// not written: the block's points with |d| <= W, padding bits clear). Called once with
/// every active block; a device kernel adds its kernel, upload and download seconds to
/// band.timings.
using BandBlockKernel = std::function<void(SparseBandField& band, size_t first, size_t last)>;

/// Samples the band of width `width` > 0 of `lattice`: the active blocks with `blocks`, or,
/// when it is empty, with `sampler`'s point queries; the outside with its point queries.
/// The band holds the channels plan.channels asks for (the gradient and the closest
/// triangle are neither kept nor, by a device kernel, downloaded without them); band_mask
/// always.
SparseBandField sample_sparse_band(const BoundSampler& sampler, const Lattice& lattice, double width,
                                   const SparseBandPlan& plan = {}, const BandBlockKernel& blocks = {});

}  // namespace sdf
