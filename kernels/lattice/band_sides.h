/// @file band_sides.h
/// @brief The sides of a sparse band's points that lie beyond the band, taken from their
/// neighbours in the block (core/sampling/sparse_band.h), written once for host and device:
/// the CPU BVH's block kernel sweeps a block with it, the CUDA one runs a thread per point.
///
/// Why it is exact. A point p farther than W from the surface, with W at least the coset's
/// spacing h, is joined to each coset neighbour q (h away) by a segment that stays farther
/// than W - h >= 0 from the surface: p and q lie on one side of it. Where the sign is the
/// side of a solid (the pseudonormal sign of choose_sign_mode's solids) p's sign is q's.
/// The points of a block without a side of their own form components whose neighbours in
/// the block all have one (a component stops only at such points or at the block's faces),
/// so one point with a side in the block gives every point one; a block of such points only
/// needs the side of one of them.
#pragma once

#include <limits>

#include "kernels/lattice/band_blocks.h"

namespace sdf {

/// A block point's side while the band's sides are spread.
enum BandSide : signed char {
    kBandSideNone = 0,      ///< not known yet: the point's side comes from its neighbours
    kBandSideInside = -1,   ///< negative distance
    kBandSideOutside = 1,   ///< positive distance
    kBandSidePadding = 2,   ///< no lattice point (beyond the coset's resolution): never a source
};

SDF_CPU_GPU SDF_INLINE bool band_side_known(signed char s) { return s == kBandSideInside || s == kBandSideOutside; }

/// The side point `local` (block-local, x fastest) takes from its six neighbours in the
/// block, or kBandSideNone when none has one yet. `side(i)` reads point i's side.
template <typename SideOf>
SDF_CPU_GPU SDF_INLINE signed char neighbour_side(const SideOf& side, int local) {
    const Int3 o = BandBlockGrid::local_offset(local);
    const int c[3] = {o.x, o.y, o.z};
    for (int a = 0; a < 3; ++a) {
        const int stride = 1 << (kBandBlockLog2 * a);
        if (c[a] > 0 && band_side_known(side(local - stride))) return side(local - stride);
        if (c[a] + 1 < kBandBlockDim && band_side_known(side(local + stride))) return side(local + stride);
    }
    return kBandSideNone;
}

/// The squared radius a search bounded by the band starts with (its points find no triangle
/// when they lie beyond the band, and then take their sides from their neighbours): a
/// triangle whose T distance from a point is at least its root lies farther than `width`
/// from it. The allowance is 256 epsilon of the magnitudes (the float search is exact relative
/// to them; wider than the GPU brick skip's 64 epsilon and, in float, the CPU probes' relative
/// 1e-5 of W alone) plus the sliver reach (how much farther than the true nearest a search's
/// nearest may be, FloatSearchBound::sliver_reach_*). `scale` bounds every |coordinate| of the
/// points and of the mesh.
template <typename T>
inline double band_search_bound_squared(double width, double scale, double sliver_reach) {
    const double e = 256.0 * double(std::numeric_limits<T>::epsilon());
    const double r = (width + sliver_reach + e * scale) / (1.0 - e) * (1.0 + 1e-6);
    return r * r;
}

}  // namespace sdf
