/// @file sparse_vdb_file.h
/// @brief A sparse narrow band (core/sampling/sparse_band.h) written as an OpenVDB level set
/// straight from its blocks, never densified: memory and time grow with the band.
///
/// Per coset (CC: one grid; BCC: "primary" and "secondary", named as write_vdb_file names a
/// dense field's sub-grids, volume_grids.h) a FloatGrid "distance[_part]" of class level set,
/// background W, the coset's transform (voxel size h, translated to the coset's first point):
/// - an active block is a leaf (8^3 = OpenVDB's LeafNode); its points within the band
///   (the band's mask, SparseBandField::band_mask) are active voxels holding float(d), its other
///   points inactive voxels at +-W, its padding (beyond the lattice) inactive at +W;
/// - a mixed block is a leaf of inactive voxels at +-W, point by point;
/// - an inside tile is an inactive level-1 tile (8^3 voxels) at -W, an outside tile is the
///   background; uniform tiles are then pruned into larger ones (value preserving).
/// Extra grids on the active blocks' band points: "gradient[_part]" (Vec3SGrid, background 0)
/// and "closest_triangle[_part]" (Int32Grid, background kOutsideBandTriangle).
#pragma once

#include <string>

#include "core/sampling/sparse_band.h"
#include "harness/io/atomic_file.h"

namespace sdf {

struct SparseVdbOptions {
    bool gradient = true;           ///< write the gradient grids: refused of a band without them (BandChannels)
    bool closest_triangle = false;  ///< write the closest triangle grids: refused of a band without them
    Overwrite overwrite = Overwrite::Forbid;
};

struct SparseVdbCounts {
    int64_t leaves = 0;         ///< active and mixed blocks, every grid
    int64_t active_voxels = 0;  ///< band points
    int64_t inside_tiles = 0;   ///< inside blocks written as -W tiles (before pruning)
};

/// Writes `band` to `path` (.vdb) atomically (a temporary beside it, then renamed; an existing
/// file is refused unless options.overwrite allows it). Without OpenVDB it throws, naming it;
/// so does options.gradient (closest_triangle) of a band without that channel
/// (std::invalid_argument).
SparseVdbCounts write_sparse_band_vdb(const SparseBandField& band, const std::string& path,
                                      const SparseVdbOptions& options = {});

}  // namespace sdf
