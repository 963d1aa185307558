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

/// write_sparse_band_nvdb, whose leaves are filled and written a window of lower nodes at a
/// time, with windows of `window_leaves` leaves (at least one lower node's, 4096): for tests
/// that stream a small band through many windows.
SparseNvdbCounts write_sparse_band_nvdb_windows(const SparseBandField& band, const std::string& path, Overwrite overwrite,
                                                uint64_t window_leaves);

}  // namespace sdf
