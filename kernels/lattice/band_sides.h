/// @file band_sides.h
/// @brief The sides of a sparse band's points that lie beyond the band, taken from their
/// neighbours in the block (core/sampling/sparse_band.h), written once for host and device:
/// a block's sides as bit layers, spread one step at a time (band_layer_step). The CPU BVH's
/// block kernel spreads a block's layers in turn (BandSideLayers::spread), the CUDA one a
/// warp per block, a lane per layer and side.
///
/// Why it is exact. A point p farther than W from the surface, with W at least the coset's
/// spacing h, is joined to each coset neighbour q (h away) by a segment that stays farther
/// than W - h >= 0 from the surface: p and q lie on one side of it. Where the sign is the
/// side of a solid (the pseudonormal sign of choose_sign_mode's solids) p's sign is q's.
/// The points of a block without a side of their own form components whose neighbours in
/// the block all have one (a component stops only at such points or at the block's faces),
/// so one point with a side in the block gives every point one; a block of such points only
/// needs the side of one of them. Both sides never reach one point (its neighbours lie on
/// its side), which the spread checks.
#pragma once

#include <cstdint>

#include "kernels/lattice/band_blocks.h"

namespace sdf {

/// A block point's side while the band's sides are spread.
enum BandSide : signed char {
    kBandSideNone = 0,      ///< not known yet: the point's side comes from its neighbours
    kBandSideInside = -1,   ///< negative distance
    kBandSideOutside = 1,   ///< positive distance
};

/// Bit x + 8 y of a block's layer z stands for block-local point x + 8 y + 64 z.
inline constexpr uint64_t kLayerColumnFirst = 0x0101010101010101ull;  ///< the layer's points with x = 0
inline constexpr uint64_t kLayerColumnLast = 0x8080808080808080ull;   ///< with x = 7
static_assert(kBandBlockDim * kBandBlockDim == 64, "a block's layer is one 64-bit word");

/// The points of a layer one step from `layer`'s: its neighbours along x and y within the
/// layer, and the points of the layers below and above (`below`, `above`: 0 at the block's faces).
SDF_CPU_GPU SDF_INLINE uint64_t band_layer_step(uint64_t layer, uint64_t below, uint64_t above) {
    return ((layer << 1) & ~kLayerColumnFirst) | ((layer >> 1) & ~kLayerColumnLast) | (layer << kBandBlockDim) |
           (layer >> kBandBlockDim) | below | above;
}

/// A block's sides while they are spread: the points known inside and outside, and the
/// open points (beyond the band: their side comes from their neighbours). Padding is none.
struct BandSideLayers {
    uint64_t inside[kBandBlockDim]{}, outside[kBandBlockDim]{}, open[kBandBlockDim]{};

    SDF_CPU_GPU static int layer_of(int local) { return local >> (2 * kBandBlockLog2); }
    SDF_CPU_GPU static uint64_t bit_of(int local) { return uint64_t(1) << (local & 63); }
    SDF_CPU_GPU void set(int local, BandSide side) {
        uint64_t* layers = side == kBandSideInside ? inside : side == kBandSideOutside ? outside : open;
        layers[layer_of(local)] |= bit_of(local);
    }
    SDF_CPU_GPU bool any_known() const {
        uint64_t any = 0;
        for (int z = 0; z < kBandBlockDim; ++z) any |= inside[z] | outside[z];
        return any != 0;
    }
    /// Spreads both sides into the open points until neither grows; false when an open point
    /// is left without a side or both reach one (never, by the argument above).
    SDF_CPU_GPU bool spread() {
        for (bool grew = true; grew;) {
            grew = false;
            uint64_t* const sides[2] = {inside, outside};
            for (uint64_t* side : sides)
                for (int z = 0; z < kBandBlockDim; ++z) {
                    const uint64_t below = z > 0 ? side[z - 1] : 0, above = z + 1 < kBandBlockDim ? side[z + 1] : 0;
                    const uint64_t reached = band_layer_step(side[z], below, above) & open[z] & ~side[z];
                    side[z] |= reached;
                    grew = grew || reached != 0;
                }
        }
        uint64_t wrong = 0;
        for (int z = 0; z < kBandBlockDim; ++z) wrong |= (open[z] & ~(inside[z] | outside[z])) | (inside[z] & outside[z]);
        return wrong == 0;
    }
};

}  // namespace sdf
