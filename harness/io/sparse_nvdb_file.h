/// @file sparse_nvdb_file.h
/// @brief A sparse narrow band (core/sampling/sparse_band.h) written as a NanoVDB level set
/// (.nvdb) straight from its blocks, as sparse_vdb_file.h writes the OpenVDB one: the same
/// grids, leaves, active voxels and values, never densified.
///
/// Per coset (CC: one grid; BCC: "distance_primary" and "distance_secondary") a NanoVDB
/// FloatGrid "distance[_part]" of class level set, background W, whose map is the coset's
/// exact transform (voxel size h, translated to the coset's first point, as volume_grids.h):
/// an active block is a leaf whose band points (the band's mask, SparseBandField::band_mask) are
/// active voxels holding float(d), its other points inactive at +-W and its padding inactive
/// at +W; a mixed block is a leaf of inactive voxels at +-W; an inside tile is an inactive
/// tile of one leaf's extent at -W; every other block is the background +W. Each grid is laid
/// out on the host, breadth first, from the band's blocks (sparse_nvdb_grids.h: the bytes
/// NanoVDB's tools/GridBuilder.h and tools/CreateNanoGrid.h make of the same tree) and
/// streamed: the leaves are filled on every core a window of lower nodes at a time while the
/// previous window is written, and each grid's nodes above them and its segment header are
/// written last, once its statistics are known. The file holds the bytes NanoVDB's
/// io::writeGrids (uncompressed) writes, and the process holds the band, the grids' upper and
/// lower nodes and two windows (2 x 67 MiB), never a grid's leaves. Distance only: no
/// gradient or triangle grids.
#pragma once

#include <string>

#include "core/sampling/sparse_band.h"
#include "harness/io/atomic_file.h"

namespace sdf {

struct SparseNvdbCounts {
    int64_t leaves = 0;         ///< active and mixed blocks, every grid
    int64_t active_voxels = 0;  ///< band points
    int64_t inside_tiles = 0;   ///< inside blocks written as -W tiles
    int64_t bytes = 0;          ///< the grids' size in memory (the file holds them uncompressed)
};

/// Whether this build writes .nvdb (NanoVDB's headers found at configure time).
bool nanovdb_available();

/// Writes `band` to `path` (.nvdb) atomically (a temporary beside it, then renamed; an existing
/// file is refused unless `overwrite` allows it). Without NanoVDB it throws, naming it.
SparseNvdbCounts write_sparse_band_nvdb(const SparseBandField& band, const std::string& path,
                                        Overwrite overwrite = Overwrite::Forbid);

}  // namespace sdf
