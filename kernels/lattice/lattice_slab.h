/// @file lattice_slab.h
/// @brief A slab of a lattice: the unit of work of a distributed run (harness/distributed).
///
/// A slab is the primary z-planes [z_begin, z_end) and, on a BCC lattice, the secondary
/// planes k in [z_begin, min(z_end, Rz - 1)) (plane k lies between primary planes k and
/// k + 1). Slabs that tile [0, Rz) therefore tile every point of the lattice once. A slab's
/// points are stored compactly: its primary planes, then its secondary planes, each in the
/// lattice's own order (x fastest), so that both parts are contiguous ranges of the lattice's
/// storage (kernels/lattice/lattice.h) and of its field files.
///
/// The blocks of a slab start at the slab's integer coordinates, so every point's position
/// is computed from the same integers as in a whole-lattice run: a slab's samples are the
/// whole run's samples, bit for bit.
#pragma once

#include <algorithm>
#include <cstdint>

#include "kernels/lattice/sampling_grid.h"

namespace sdf {

struct LatticeSlab {
    int z_begin = 0;  ///< first primary z-plane
    int z_end = 0;    ///< one past the last primary z-plane
};

/// One contiguous run of lattice storage: [offset, offset + count).
struct StorageRange {
    int64_t offset = 0;
    int64_t count = 0;
};

inline LatticeSlab whole_lattice_slab(const Lattice& lattice) { return {0, lattice.resolution.z}; }

inline bool is_whole_lattice(const Lattice& lattice, const LatticeSlab& slab) {
    return slab.z_begin == 0 && slab.z_end == lattice.resolution.z;
}

/// Secondary z-planes of the slab (0 on CC, and on BCC for a slab holding only the last plane).
inline int slab_secondary_planes(const Lattice& lattice, const LatticeSlab& slab) {
    if (lattice.secondary_count() == 0) return 0;
    return std::max(0, std::min(slab.z_end, lattice.resolution.z - 1) - slab.z_begin);
}

/// Where the slab's primary (part 0) and secondary (part 1) points lie in lattice storage.
inline StorageRange slab_storage(const Lattice& lattice, const LatticeSlab& slab, int part) {
    if (part == 0) {
        const int64_t plane = int64_t(lattice.resolution.x) * lattice.resolution.y;
        return {plane * slab.z_begin, plane * (slab.z_end - slab.z_begin)};
    }
    const Int3 s = lattice.secondary_resolution();
    const int64_t plane = lattice.secondary_count() > 0 ? int64_t(s.x) * s.y : 0;
    return {lattice.primary_count() + plane * slab.z_begin, plane * slab_secondary_planes(lattice, slab)};
}

inline int64_t slab_point_count(const Lattice& lattice, const LatticeSlab& slab) {
    return slab_storage(lattice, slab, 0).count + slab_storage(lattice, slab, 1).count;
}

/// The blocks that sample `slab`, their output offsets relative to the slab's compact
/// storage. The whole lattice gets exactly sampling_blocks(); a part of a BCC lattice is
/// sampled as two grids whatever the strategy (strategy A computes the same positions and
/// discards the rest, so the samples are the same). Returns the number of blocks.
inline int slab_sampling_blocks(const Lattice& lattice, BccStrategy strategy, const LatticeSlab& slab, GridBlock out[kMaxSamplingBlocks]) {
    if (is_whole_lattice(lattice, slab)) return sampling_blocks(lattice, strategy, out);
    const int nz = slab.z_end - slab.z_begin;
    out[0] = GridBlock{{0, 0, 2 * slab.z_begin}, 2, {lattice.resolution.x, lattice.resolution.y, nz}, 0, false};
    const int secondary = slab_secondary_planes(lattice, slab);
    if (secondary == 0) return 1;
    const Int3 s = lattice.secondary_resolution();
    out[1] = GridBlock{{1, 1, 2 * slab.z_begin + 1}, 2, {s.x, s.y, secondary}, slab_storage(lattice, slab, 0).count, false};
    return 2;
}

}  // namespace sdf
