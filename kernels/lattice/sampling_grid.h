/// @file sampling_grid.h
/// @brief Regular blocks of sample points, the unit of work of every sampler backend.
///
/// A lattice is sampled as one or more GridBlocks (thesis section 3.3):
///   - CC: one block, the lattice itself.
///   - BCC strategy B (Figure 3-3 B): two blocks, the primary grid and the secondary grid
///     shifted by h/2.
///   - BCC strategy A (Figure 3-3 A): one CC block of twice the resolution (2Rx x 2Ry x 2Rz, as
///     the thesis writes it; 2R-1 per axis would suffice, so its last planes lie h/2 beyond
///     the domain) at spacing h/2; points that are not BCC points are computed and discarded.
/// Positions come from Lattice::position_of_coords, so every strategy and backend sees the
/// same positions bit for bit.
#pragma once

#include <cstdint>

#include "kernels/lattice/lattice.h"

namespace sdf {

enum class BccStrategy : int {
    TwoGrids = 0,        ///< thesis Figure 3-3 B
    DoubleResolution = 1 ///< thesis Figure 3-3 A
};

struct GridBlock {
    Int3 first{};        ///< integer coordinates (units of h/2) of point (0,0,0)
    int step{2};         ///< coordinate step between neighbouring points (2 = h, 1 = h/2)
    Int3 resolution{};   ///< points per axis in this block
    int64_t output_offset{0};  ///< storage index of the block's first point (direct blocks)
    bool scatter{false}; ///< true: map each point through Lattice::index_of_coords (may discard)

    SDF_CPU_GPU int64_t count() const { return int64_t(resolution.x) * resolution.y * resolution.z; }

    SDF_CPU_GPU Int3 coords(int64_t local) const {
        const int i = int(local % resolution.x);
        const int j = int((local / resolution.x) % resolution.y);
        const int k = int(local / (int64_t(resolution.x) * resolution.y));
        return {first.x + step * i, first.y + step * j, first.z + step * k};
    }

    /// Storage index in the lattice of block point `local`, or -1 if it is discarded.
    SDF_CPU_GPU int64_t output_index(const Lattice& lattice, int64_t local) const {
        return scatter ? lattice.index_of_coords(coords(local)) : output_offset + local;
    }
};

/// The most blocks a lattice is sampled as: one per coset (BCC strategy B), so a new lattice
/// kind changes its row of kLatticeKinds only.
inline constexpr int kMaxSamplingBlocks = kMaxLatticeCosets;

/// The blocks that sample `lattice` (at most kMaxSamplingBlocks). Returns the number of blocks.
inline int sampling_blocks(const Lattice& lattice, BccStrategy strategy, GridBlock out[kMaxSamplingBlocks]) {
    switch (lattice.type) {
        case LatticeType::CC:
            out[0] = GridBlock{{0, 0, 0}, 2, lattice.resolution, 0, false};
            return 1;
        case LatticeType::BCC:
            if (strategy == BccStrategy::DoubleResolution) {
                const Int3 r = lattice.resolution;
                out[0] = GridBlock{{0, 0, 0}, 1, {2 * r.x, 2 * r.y, 2 * r.z}, 0, true};
                return 1;
            }
            out[0] = GridBlock{{0, 0, 0}, 2, lattice.resolution, 0, false};
            out[1] = GridBlock{{1, 1, 1}, 2, lattice.secondary_resolution(), lattice.primary_count(), false};
            return lattice.secondary_count() > 0 ? 2 : 1;
    }
    return 0;  // not reached: every lattice type has its case
}

}  // namespace sdf
