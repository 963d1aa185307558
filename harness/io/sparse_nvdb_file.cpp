/// @file sparse_nvdb_file.cpp
/// @brief The sparse band's NanoVDB writer (sparse_nvdb_file.h): NanoVDB's host grid builder
/// fed the blocks directly, converted to a NanoGrid<float>, written to a temporary, synced and
/// placed (write_through_temporary).
#include "harness/io/sparse_nvdb_file.h"

#include <atomic>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "core/parallel/parallel_for.h"
#include "harness/io/field_file.h"
#include "harness/io/volume_grids.h"

#if SDF_HAVE_NANOVDB
#include <nanovdb/NanoVDB.h>
#include <nanovdb/io/IO.h>
#include <nanovdb/tools/CreateNanoGrid.h>
#include <nanovdb/tools/GridBuilder.h>
#endif

namespace sdf {

#if SDF_HAVE_NANOVDB
namespace {

using BuildGrid = nanovdb::tools::build::Grid<float>;
using BuildLeaf = BuildGrid::Node0;
static_assert(BuildLeaf::DIM == uint32_t(kBandBlockDim), "a band block is a NanoVDB leaf");

/// NanoVDB's leaf offset of the block-local point `local` (ours runs x fastest, NanoVDB's z).
uint32_t leaf_offset(int local) {
    const Int3 o = BandLayout::local_offset(local);
    return uint32_t((o.x << (2 * kBandBlockLog2)) | (o.y << kBandBlockLog2) | o.z);
}

nanovdb::Coord block_origin(const BandBlockCoords& b) {
    return nanovdb::Coord(b.block.x * kBandBlockDim, b.block.y * kBandBlockDim, b.block.z * kBandBlockDim);
}

void set_inactive(BuildLeaf& leaf, uint32_t offset, float value) {
    leaf.mValues[offset] = value;
    leaf.mValueMask.setOff(offset);
}

// path: the temporary written; target: the name the messages give.
void write_grids(const SparseBandField& band, const std::string& path, const std::string& target, SparseNvdbCounts& counts) {
    const BandLayout& layout = band.layout();
    const std::vector<VolumeGrid> parts = volume_grids(band.lattice);
    if (int(parts.size()) != layout.cosets()) throw std::logic_error(path + ": the band's cosets are not the lattice's grids");
    const float w = float(band.width);
    std::vector<std::unique_ptr<BuildGrid>> grids;
    for (int c = 0; c < layout.cosets(); ++c) {
        const VolumeGrid& g = parts[size_t(c)];
        grids.push_back(std::make_unique<BuildGrid>(w, g.part.empty() ? "distance" : "distance_" + g.part,
                                                    nanovdb::GridClass::LevelSet));
        grids.back()->setTransform(g.spacing, nanovdb::Vec3d(g.origin.x, g.origin.y, g.origin.z));
    }
    // Active blocks: leaves whose band points are active voxels; mixed blocks: leaves of
    // inactive voxels, each on its side. Each leaf is made (every voxel inactive at the
    // background +W) and filled on every core, then linked into its grid's tree in block
    // order on one thread (the tree's nodes are shared), as NanoVDB's own builders do: at
    // 8192^3, 8.2M leaves, 16 GiB, and 4.2G voxels.
    const size_t active = band.active.size(), leaf_count = active + band.mixed.size();
    std::vector<BuildLeaf*> leaves(leaf_count, nullptr);
    std::vector<int> coset(leaf_count);
    std::atomic<int64_t> active_voxels{0};
    try {
        parallel_for(int64_t(leaf_count), 1024, 0, [&](int64_t i0, int64_t i1) {
            int64_t on = 0;
            for (int64_t i = i0; i < i1; ++i) {
                const bool is_active = size_t(i) < active;
                const int64_t id = is_active ? band.active[size_t(i)] : band.mixed[size_t(i) - active];
                const BandBlockCoords b = layout.block_coords(id);
                const Int3 points = layout.block_points(b);
                const bool whole = BandBlockGrid::whole(points);
                coset[size_t(i)] = b.coset;
                BuildLeaf& leaf = *(leaves[size_t(i)] = new BuildLeaf(block_origin(b), w, false));
                if (!is_active) {
                    const BandSignMask& inside = band.mixed_inside[size_t(i) - active];
                    for (int local = 0; local < kBandBlockPoints; ++local)
                        if ((whole || BandBlockGrid::within(points, local)) && ((inside[size_t(local >> 6)] >> (local & 63)) & 1))
                            set_inactive(leaf, leaf_offset(local), -w);
                    continue;
                }
                for (int local = 0; local < kBandBlockPoints; ++local) {
                    if (!whole && !BandBlockGrid::within(points, local)) continue;  // padding: background +W
                    const size_t at = size_t(i) * kBandBlockPoints + size_t(local);
                    const float d = float(band.distance[at]);
                    if (!band.in_band(size_t(i), local)) {
                        set_inactive(leaf, leaf_offset(local), d);  // +-W, its side
                        continue;
                    }
                    leaf.setValue(leaf_offset(local), d);  // on
                    ++on;
                }
            }
            active_voxels += on;
        });
        // Linked in block order; addNode takes each leaf (nulls its pointer).
        for (size_t i = 0; i < leaf_count; ++i) grids[size_t(coset[i])]->tree().root().addNode(leaves[i]);
    } catch (...) {
        for (BuildLeaf* leaf : leaves) delete leaf;  // those not yet in a tree
        throw;
    }
    counts.active_voxels += active_voxels.load();
    counts.leaves += int64_t(leaf_count);
    // Inside tiles: -W tiles of one leaf's extent (level 1). The builder makes a missing lower
    // node with the tile's value for all its 4096 tiles, so the node is first made with a +W
    // (background) tile, then that tile set to -W.
    for (size_t word = 0; word < band.inside_tiles.size(); ++word) {
        for (uint64_t bits = band.inside_tiles[word]; bits; bits &= bits - 1) {
            const int64_t id = int64_t(word) * 64 + __builtin_ctzll(bits);
            if (id >= layout.block_count() || band.find_active(id) >= 0 || band.find_mixed(id) >= 0) continue;
            const BandBlockCoords b = layout.block_coords(id);
            BuildGrid& grid = *grids[size_t(b.coset)];
            grid.tree().root().addTile<1>(block_origin(b), w, false);
            grid.tree().root().addTile<1>(block_origin(b), -w, false);
            ++counts.inside_tiles;
        }
    }
    std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
    for (const std::unique_ptr<BuildGrid>& grid : grids) {
        handles.push_back(nanovdb::tools::createNanoGrid(*grid));
        counts.bytes += int64_t(handles.back().bufferSize());
    }
    // NanoVDB's file-name overload neither checks its stream nor reports a short write: a full
    // disk would be placed as a whole file. Our own stream, checked after closing, does not.
    std::ofstream os(path, std::ios::binary | std::ios::trunc);
    if (!os) throw std::runtime_error(target + ": cannot open a file beside it for writing");
    nanovdb::io::writeGrids(os, handles);
    os.close();
    if (!os) throw std::runtime_error(target + ": writing the NanoVDB grids failed (disk full?)");
}

}  // namespace

bool nanovdb_available() { return true; }

SparseNvdbCounts write_sparse_band_nvdb(const SparseBandField& band, const std::string& path, Overwrite overwrite) {
    if (!(band.width > 0)) throw std::invalid_argument(path + ": a sparse band needs a width W > 0");
    band.require_channels({false, false}, path + ": the distance grids");  // the arrays match the active blocks
    require_representable_band(band.width, FieldDtype::Float32, path + ": the band's width (a .nvdb stores float32)");
    SparseNvdbCounts counts;
    write_through_temporary(path, overwrite,
                            [&](const std::string& temporary) { write_grids(band, temporary, path, counts); });
    return counts;
}

#else

bool nanovdb_available() { return false; }

SparseNvdbCounts write_sparse_band_nvdb(const SparseBandField&, const std::string& path, Overwrite) {
    throw std::runtime_error(path + ": this build has no NanoVDB support (its headers were not found at configure time: "
                                    "set SDF_NANOVDB_DIR to the folder holding nanovdb/NanoVDB.h)");
}

#endif

}  // namespace sdf
