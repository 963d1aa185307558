/// @file sparse_nvdb_grids.h
/// @brief The sparse band's NanoVDB grids, as sparse_nvdb_file.h writes them: for code that
/// has NanoVDB's headers on its include path (SDF_HAVE_NANOVDB builds: the writer and its
/// test). The grids are laid out breadth first straight from the band's blocks, with no
/// intermediate tree: the nodes, offsets, statistics (tools/GridStats.h) and checksum
/// (tools/GridChecksum.h) NanoVDB's own conversion of the same tree gives, byte for byte.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nanovdb/GridHandle.h>
#include <nanovdb/HostBuffer.h>
#include <nanovdb/NanoVDB.h>
#include <nanovdb/tools/GridStats.h>

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

/// Refuses (std::invalid_argument naming `what`) a band whose arrays do not match its
/// blocks and lattice, before any of them is read by block: the grids' input may come from a
/// file or a caller's own band.
void check_band_for_nanovdb(const SparseBandField& band, const std::string& what);

/// A node's active bounding box and the statistics of its active values: GridStats's own
/// (StatsMode::All), which NanoVDB's conversion computes on one thread; here each lower node's
/// leaves and each upper node's lower nodes on every core, in the order GridStats visits
/// them, so that every float written is the one it writes.
struct NanoNodeStats {
    nanovdb::tools::Stats<float> stats;
    nanovdb::CoordBBox bbox;
    NanoNodeStats& add(const NanoNodeStats& other);
};

/// The band's grids planned: every grid's nodes in NanoVDB's breadth-first order and its byte
/// layout (CreateNanoGrid's, without blind data). A grid is then built in two parts: its top
/// (grid, tree, root, upper and lower nodes: every byte before its leaves) in one buffer, and
/// its leaves, a lower node's at a time, wherever the caller puts them (the grid's own buffer,
/// or a window the writer streams to the file).
class SparseNanoPlan {
public:
    struct GridPlan {
        size_t upper_begin = 0, upper_end = 0, lower_begin = 0, lower_end = 0, leaf_begin = 0, leaf_end = 0;
        uint64_t tree_at = 0, root_at = 0, upper_at = 0, lower_at = 0, leaf_at = 0, size = 0;
        std::string name;
        nanovdb::Map map;
        uint64_t uppers() const { return upper_end - upper_begin; }
        uint64_t lowers() const { return lower_end - lower_begin; }
        uint64_t leaves() const { return leaf_end - leaf_begin; }
    };

    /// `what` names the grids in messages (the file, for the writer). The band must outlive
    /// the plan.
    SparseNanoPlan(const SparseBandField& band, const std::string& what);
    ~SparseNanoPlan();

    int grids() const { return int(grids_.size()); }
    const GridPlan& grid(int c) const { return grids_[size_t(c)]; }
    /// The leaves of lower node n of grid c: [first, last) of the grid's leaves.
    std::pair<size_t, size_t> leaves_of_lower(int c, size_t n) const;
    /// Lower node n of grid c into `top`, its leaves (leaves_of_lower) filled at `leaves`:
    /// +W tiles (the background), -W where a block is an inside tile, the leaves as children
    /// (offsets into the grid's layout, wherever the leaves are now); then, as
    /// tools/GridStats.h computes them, each leaf's and the node's box and statistics.
    /// `on` and `inside` count the active voxels and the inside tiles.
    NanoNodeStats build_lower(int c, size_t n, char* top, nanovdb::NanoLeaf<float>* leaves, int64_t& on, int64_t& inside) const;
    /// The rest of grid c's top once its lower nodes are built: the upper nodes (+W tiles,
    /// the lower nodes as children), the root, the tree and the grid, with GridStats's
    /// statistics, boxes and flags, and the checksum CreateNanoGrid leaves (CheckMode::Default).
    void finish(int c, char* top, const std::vector<NanoNodeStats>& lower_stats, int64_t voxels) const;

private:
    struct Nodes;  ///< the sorted node lists and their keys (sparse_nvdb_grids.cpp)
    const SparseBandField& band_;
    std::unique_ptr<const Nodes> nodes_;
    std::vector<GridPlan> grids_;
};

}  // namespace sdf
