/// @file sparse_nvdb_grids.h
/// @brief The sparse band's NanoVDB grids in memory, as sparse_nvdb_file.h writes them: for
/// code that has NanoVDB's headers on its include path (SDF_HAVE_NANOVDB builds: the writer
/// and its test). The grids are laid out in place, breadth first, from the band's blocks,
/// with no intermediate tree: the nodes, offsets, statistics (tools/GridStats.h) and checksum
/// (tools/GridChecksum.h) NanoVDB's own conversion of the same tree gives, byte for byte.
#pragma once

#include <vector>

#include <nanovdb/GridHandle.h>
#include <nanovdb/HostBuffer.h>

#include "harness/io/sparse_nvdb_file.h"

namespace sdf {

/// One float level-set grid per coset (CC "distance"; BCC "distance_primary" and
/// "distance_secondary"), as sparse_nvdb_file.h describes; `counts` (may be null) receives
/// the leaves, active voxels, inside tiles and bytes.
std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> sparse_band_nanogrids(const SparseBandField& band,
                                                                           SparseNvdbCounts* counts = nullptr);

}  // namespace sdf
