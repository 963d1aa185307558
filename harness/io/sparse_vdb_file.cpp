/// @file sparse_vdb_file.cpp
/// @brief The sparse band's OpenVDB writer (sparse_vdb_file.h): leaves and tiles built from
/// the blocks directly, then written to a temporary, synced and placed (write_through_temporary).
#include "harness/io/sparse_vdb_file.h"

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "core/parallel/parallel_for.h"
#include "harness/io/field_file.h"
#include "harness/io/volume_grids.h"

#if SDF_HAVE_OPENVDB
#include <openvdb/openvdb.h>
#include <openvdb/tools/Prune.h>

#include "harness/io/vdb_grid_file.h"
#endif

namespace sdf {

#if SDF_HAVE_OPENVDB
namespace {

using FloatLeaf = openvdb::FloatTree::LeafNodeType;
using Vec3Leaf = openvdb::Vec3STree::LeafNodeType;
using Int32Leaf = openvdb::Int32Tree::LeafNodeType;
static_assert(FloatLeaf::DIM == kBandBlockDim, "a band block is an OpenVDB leaf");

/// OpenVDB's leaf offset of the block-local point `local` (ours runs x fastest, OpenVDB's z).
openvdb::Index leaf_offset(int local) {
    const Int3 o = BandLayout::local_offset(local);
    return openvdb::Index((o.x << (2 * kBandBlockLog2)) | (o.y << kBandBlockLog2) | o.z);
}

openvdb::Coord block_origin(const BandBlockCoords& b) {
    return openvdb::Coord(b.block.x * kBandBlockDim, b.block.y * kBandBlockDim, b.block.z * kBandBlockDim);
}

/// One coset's grids.
struct CosetGrids {
    openvdb::FloatGrid::Ptr distance;
    openvdb::Vec3SGrid::Ptr gradient;
    openvdb::Int32Grid::Ptr triangle;
};

void describe(openvdb::GridBase& grid, const std::string& name, const VolumeGrid& g, const Lattice& lattice) {
    openvdb::math::Transform::Ptr t = openvdb::math::Transform::createLinearTransform(g.spacing);
    t->postTranslate(openvdb::Vec3d(g.origin.x, g.origin.y, g.origin.z));
    grid.setTransform(t);
    grid.setName(g.part.empty() ? name : name + "_" + g.part);
    grid.insertMeta("sdf_lattice", openvdb::StringMetadata(lattice_type_name(lattice.type)));
    if (!g.part.empty()) grid.insertMeta("sdf_subgrid", openvdb::StringMetadata(g.part));
    grid.insertMeta("sdf_units", openvdb::StringMetadata("mesh units; distance negative inside"));
}

void write_grids(const SparseBandField& band, const std::string& path, const SparseVdbOptions& options,
                 SparseVdbCounts& counts) {
    const BandLayout& layout = band.layout();
    const std::vector<VolumeGrid> parts = volume_grids(band.lattice);
    if (int(parts.size()) != layout.cosets()) throw std::logic_error(path + ": the band's cosets are not the lattice's grids");
    for (int c = 0; c < layout.cosets(); ++c) {
        const BandCoset& s = layout.coset(c);
        const VolumeGrid& g = parts[size_t(c)];
        if (g.resolution.x != s.points.x || g.resolution.y != s.points.y || g.resolution.z != s.points.z)
            throw std::logic_error(path + ": coset " + std::to_string(c) + " is not the lattice's grid " + g.part);
    }
    const float w = float(band.width);
    const bool gradient = options.gradient;  // checked against the band's channels by write_sparse_band_vdb
    std::vector<CosetGrids> grids(size_t(layout.cosets()));
    for (CosetGrids& cg : grids) {
        cg.distance = openvdb::FloatGrid::create(w);
        if (gradient) cg.gradient = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        if (options.closest_triangle) cg.triangle = openvdb::Int32Grid::create(kOutsideBandTriangle);
    }
    // Active blocks: leaves whose band points are active voxels. The leaves are made and
    // added in order on one thread (the trees' nodes are shared), then filled on every core
    // (each leaf its own). A block's gradient and triangle leaves exist where it has a band
    // point.
    struct Leaves {
        FloatLeaf* distance;
        Vec3Leaf* gradient;
        Int32Leaf* triangle;
        Int3 points;
    };
    std::vector<Leaves> leaves(band.active.size());
    for (size_t a = 0; a < band.active.size(); ++a) {
        const BandBlockCoords b = layout.block_coords(band.active[a]);
        CosetGrids& cg = grids[size_t(b.coset)];
        const openvdb::Coord origin = block_origin(b);
        Leaves& l = leaves[a];
        l.points = layout.block_points(b);
        l.distance = new FloatLeaf(origin, w, false);
        cg.distance->tree().addLeaf(l.distance);
        const BandPointMask& mask = band.band_mask[a];
        const bool any = std::any_of(mask.begin(), mask.end(), [](uint64_t word) { return word != 0; });
        l.gradient = gradient && any ? new Vec3Leaf(origin, openvdb::Vec3s(0.0f), false) : nullptr;
        l.triangle = cg.triangle && any ? new Int32Leaf(origin, kOutsideBandTriangle, false) : nullptr;
        if (l.gradient) cg.gradient->tree().addLeaf(l.gradient);
        if (l.triangle) cg.triangle->tree().addLeaf(l.triangle);
    }
    std::atomic<int64_t> active_voxels{0};
    parallel_for(int64_t(band.active.size()), 1024, 0, [&](int64_t a0, int64_t a1) {
        int64_t on = 0;
        for (int64_t a = a0; a < a1; ++a) {
            const Leaves& l = leaves[size_t(a)];
            const bool whole = BandBlockGrid::whole(l.points);
            for (int local = 0; local < kBandBlockPoints; ++local) {
                if (!whole && !BandBlockGrid::within(l.points, local)) continue;  // padding: background +W
                const size_t at = size_t(a) * kBandBlockPoints + size_t(local);
                const openvdb::Index offset = leaf_offset(local);
                const float d = float(band.distance[at]);
                if (!band.in_band(size_t(a), local)) {
                    l.distance->setValueOff(offset, d);  // +-W, its side
                    continue;
                }
                l.distance->setValueOn(offset, d);
                ++on;
                if (l.gradient) {
                    const Vec3d& n = band.gradient[at];
                    l.gradient->setValueOn(offset, openvdb::Vec3s(float(n.x), float(n.y), float(n.z)));
                }
                if (l.triangle) l.triangle->setValueOn(offset, band.closest_triangle[at]);
            }
        }
        active_voxels += on;
    });
    counts.active_voxels += active_voxels.load();
    counts.leaves += int64_t(band.active.size());
    // Mixed blocks: leaves of inactive voxels, each on its side.
    for (size_t m = 0; m < band.mixed.size(); ++m) {
        const BandBlockCoords b = layout.block_coords(band.mixed[m]);
        auto* leaf = new FloatLeaf(block_origin(b), w, false);
        grids[size_t(b.coset)].distance->tree().addLeaf(leaf);
        const BandSignMask& inside = band.mixed_inside[m];
        const Int3 points = layout.block_points(b);
        for (int local = 0; local < kBandBlockPoints; ++local) {
            if (!BandBlockGrid::within(points, local)) continue;
            if ((inside[size_t(local >> 6)] >> (local & 63)) & 1) leaf->setValueOff(leaf_offset(local), -w);
        }
        ++counts.leaves;
    }
    // Inside tiles: -W tiles of one leaf's extent (level 1: a tile of the lowest internal node).
    for (size_t word = 0; word < band.inside_tiles.size(); ++word) {
        for (uint64_t bits = band.inside_tiles[word]; bits; bits &= bits - 1) {
            const int64_t id = int64_t(word) * 64 + __builtin_ctzll(bits);
            if (id >= layout.block_count() || band.find_active(id) >= 0 || band.find_mixed(id) >= 0) continue;
            const BandBlockCoords b = layout.block_coords(id);
            grids[size_t(b.coset)].distance->tree().addTile(1, block_origin(b), -w, false);
            ++counts.inside_tiles;
        }
    }
    openvdb::GridPtrVec out;
    for (size_t c = 0; c < grids.size(); ++c) {
        CosetGrids& cg = grids[c];
        openvdb::tools::prune(cg.distance->tree());  // uniform tiles into larger ones; values kept
        cg.distance->setGridClass(openvdb::GRID_LEVEL_SET);
        describe(*cg.distance, "distance", parts[c], band.lattice);
        out.push_back(cg.distance);
        if (cg.gradient) {
            cg.gradient->setVectorType(openvdb::VEC_COVARIANT_NORMALIZE);
            describe(*cg.gradient, "gradient", parts[c], band.lattice);
            out.push_back(cg.gradient);
        }
        if (cg.triangle) {
            describe(*cg.triangle, "closest_triangle", parts[c], band.lattice);
            out.push_back(cg.triangle);
        }
    }
    write_vdb_grids(out, path);
}

}  // namespace

SparseVdbCounts write_sparse_band_vdb(const SparseBandField& band, const std::string& path,
                                      const SparseVdbOptions& options) {
    namespace fs = std::filesystem;
    if (!(band.width > 0)) throw std::invalid_argument(path + ": a sparse band needs a width W > 0");
    require_representable_band(band.width, FieldDtype::Float32, path + ": the band's width (a .vdb stores float32)");
    band.require_channels({options.gradient, options.closest_triangle, BandDistanceType::Float32},  // float32 grids
                          path + ": the gradient and closest triangle grids");
    if (options.overwrite == Overwrite::Forbid && fs::exists(path))
        throw std::runtime_error(path + ": already exists; refusing to overwrite a field");
    openvdb::initialize();
    SparseVdbCounts counts;
    write_through_temporary(path, options.overwrite,
                            [&](const std::string& temporary) { write_grids(band, temporary, options, counts); });
    return counts;
}

#else

SparseVdbCounts write_sparse_band_vdb(const SparseBandField& band, const std::string& path, const SparseVdbOptions& options) {
    band.require_channels({options.gradient, options.closest_triangle, BandDistanceType::Float32},
                          path + ": the gradient and closest triangle grids");  // as with OpenVDB: the caller's error first
    throw std::runtime_error(path + ": this build has no OpenVDB support (libopenvdb-dev)");
}

#endif

}  // namespace sdf
