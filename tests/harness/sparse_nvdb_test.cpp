// The sparse band's NanoVDB level set (harness/io/sparse_nvdb_file.h, issue 35) read back by
// NanoVDB's own reader (io::readGrid): at every lattice point, CC and BCC, the grid's value is
// the dense banded field's float value (exact within the band, +-W outside it with its side,
// inside tiles included) and its voxel is active exactly where the point is within the band;
// the grids are level sets with background W, named as the .vdb's, and each grid's map puts
// its voxel (i, j, k) at the lattice point's own position. 10,000 random lattice points agree
// in sign with the field. The grids, laid out in place from the band's blocks, equal byte for
// byte what NanoVDB's own builder (tools/GridBuilder.h) and conversion (tools/CreateNanoGrid.h)
// make of the same tree, and pass NanoVDB's full validator (checksum included). Built only
// where NanoVDB's headers are found (cmake/Dependencies.cmake).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <memory>
#include <random>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/io/IO.h>
#include <nanovdb/tools/CreateNanoGrid.h>
#include <nanovdb/tools/GridBuilder.h>
#include <nanovdb/tools/GridValidator.h>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "harness/io/sparse_nvdb_file.h"
#include "harness/io/sparse_nvdb_grids.h"
#include "harness/io/volume_grids.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;

struct Case {
    std::string name;
    PreparedMesh mesh;
    SignMode sign;
    LatticeType type;
    Int3 resolution;
};

SamplerOptions options(SignMode sign, double band) {
    SamplerOptions o;
    o.sign = sign;
    o.band_width = band;
    o.progress = false;
    return o;
}

std::string temp_path(const std::string& name) {
    return (fs::temp_directory_path() / ("sdf_nvdb_" + std::to_string(::getpid()) + "_" + name)).string();
}

/// The grid of lattice point `index` (coset: CC one grid, BCC even coords primary, odd
/// secondary) and its voxel, from the lattice's own coordinates (units of h/2).
std::pair<int, nanovdb::Coord> voxel_of(const Lattice& lattice, int64_t index) {
    const Int3 c = lattice.coords_of(index);
    const int coset = c.x & 1;
    return {coset, nanovdb::Coord(c.x >> 1, c.y >> 1, c.z >> 1)};
}

std::string file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The file NanoVDB's own writer (io::writeGrids) makes of grids in memory.
std::string nanovdb_file_bytes(const std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>>& handles) {
    std::ostringstream os;
    nanovdb::io::writeGrids(os, handles);
    return os.str();
}

/// NanoVDB's own way to the same grids, the reference: its host builder fed the band's blocks
/// (a leaf per active or mixed block, a -W tile per inside tile), then its conversion.
std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> reference_grids(const SparseBandField& band) {
    using BuildGrid = nanovdb::tools::build::Grid<float>;
    using BuildLeaf = BuildGrid::Node0;
    const BandLayout& layout = band.layout();
    const std::vector<VolumeGrid> parts = volume_grids(band.lattice);
    const float w = float(band.width);
    std::vector<std::unique_ptr<BuildGrid>> grids;
    for (const VolumeGrid& g : parts) {
        grids.push_back(std::make_unique<BuildGrid>(w, g.part.empty() ? "distance" : "distance_" + g.part, nanovdb::GridClass::LevelSet));
        grids.back()->setTransform(g.spacing, nanovdb::Vec3d(g.origin.x, g.origin.y, g.origin.z));
    }
    const auto origin = [](const BandBlockCoords& b) {
        return nanovdb::Coord(b.block.x * kBandBlockDim, b.block.y * kBandBlockDim, b.block.z * kBandBlockDim);
    };
    const auto offset = [](int local) {
        const Int3 o = BandLayout::local_offset(local);
        return uint32_t((o.x << 6) | (o.y << 3) | o.z);
    };
    const size_t active = band.active.size();
    for (size_t i = 0; i < active + band.mixed.size(); ++i) {
        const int64_t id = i < active ? band.active[i] : band.mixed[i - active];
        const BandBlockCoords b = layout.block_coords(id);
        auto* leaf = new BuildLeaf(origin(b), w, false);
        for (int local = 0; local < kBandBlockPoints; ++local) {
            if (layout.storage_index(id, local) < 0) continue;  // padding: +W
            const uint32_t n = offset(local);
            if (i >= active) {
                if (mask_bit(band.mixed_inside[i - active], local)) leaf->mValues[n] = -w;
            } else if (band.in_band(i, local)) {
                leaf->setValue(n, float(band.distance[i * kBandBlockPoints + size_t(local)]));
            } else {
                leaf->mValues[n] = float(band.distance[i * kBandBlockPoints + size_t(local)]);
            }
        }
        grids[size_t(b.coset)]->tree().root().addNode(leaf);
    }
    for (int64_t id = 0; id < layout.block_count(); ++id) {
        if (!band.tile_inside(id) || band.find_active(id) >= 0 || band.find_mixed(id) >= 0) continue;
        const BandBlockCoords b = layout.block_coords(id);
        grids[size_t(b.coset)]->tree().root().addTile<1>(origin(b), w, false);  // a new lower node's tiles: +W
        grids[size_t(b.coset)]->tree().root().addTile<1>(origin(b), -w, false);
    }
    std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
    for (const auto& g : grids) handles.push_back(nanovdb::tools::createNanoGrid(*g));
    return handles;
}

/// The grids laid out from the band equal NanoVDB's own (reference_grids) byte for byte, and
/// pass its full validator (checksum, node order, offsets).
void expect_nanovdbs_own_grids(const std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>>& built,
                               const std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>>& reference) {
    ASSERT_EQ(built.size(), reference.size());
    for (size_t g = 0; g < built.size(); ++g) {
        ASSERT_EQ(built[g].bufferSize(), reference[g].bufferSize()) << "grid " << g;
        const auto* a = static_cast<const unsigned char*>(built[g].data());
        const auto* b = static_cast<const unsigned char*>(reference[g].data());
        const auto differ = std::mismatch(a, a + built[g].bufferSize(), b);
        EXPECT_EQ(differ.first, a + built[g].bufferSize()) << "grid " << g << ": first different byte at " << (differ.first - a)
                                                          << " of " << built[g].bufferSize();
        ASSERT_NE(built[g].grid<float>(), nullptr);
        // NanoVDB's validator refuses a grid without leaves (its own conversion's bytes too).
        if (built[g].grid<float>()->tree().nodeCount(0) > 0) {
            EXPECT_TRUE(nanovdb::tools::isValid(built[g].grid<float>(), nanovdb::CheckMode::Full, true)) << "grid " << g;
        }
    }
}

TEST(SparseNvdb, EveryLatticePointReadBackByNanoVdbEqualsTheDenseBand) {
    // Lattices fine enough for inside tiles (8^3 points inside) and, across the bowl's
    // opening, mixed blocks; a resolution not a multiple of 8 (padding).
    const std::vector<Case> cases = {
        {"open bowl CC (winding, mixed blocks)", test::open_bowl(), SignMode::Winding, LatticeType::CC, {96, 93, 90}},
        {"open bowl BCC (winding)", test::open_bowl(), SignMode::Winding, LatticeType::BCC, {64, 64, 128}},
        {"sphere BCC (pseudonormal)", prepare_mesh(make_icosphere(3, 1.0)), SignMode::Pseudonormal, LatticeType::BCC, {60, 58, 110}},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const Lattice lattice = fit_lattice(c.type, c.resolution, c.mesh.bounds(), 0.6);
        const double w = 1.0 * lattice.spacing;
        const SparseBandField band = make_cpu_bvh_sampler(options(c.sign, 0))->bind(share(c.mesh))->sample_band_sparse(lattice, w);
        const SampledField dense = band.densify();
        const std::string path = temp_path("band.nvdb");
        fs::remove(path);
        // In memory: NanoVDB's own builder and conversion give the same bytes.
        SparseNvdbCounts in_memory;
        const auto built = sparse_band_nanogrids(band, &in_memory);
        expect_nanovdbs_own_grids(built, reference_grids(band));
        EXPECT_GT(in_memory.inside_tiles, 0);
        EXPECT_EQ(in_memory.inside_tiles, band.counts().inside_tiles);

        // The writer streams the leaves and places each grid's top last: the file is the one
        // NanoVDB's own writer makes of the grids in memory.
        const SparseNvdbCounts counts = write_sparse_band_nvdb(band, path);
        EXPECT_TRUE(file_bytes(path) == nanovdb_file_bytes(built)) << "the streamed file differs from io::writeGrids'";
        EXPECT_EQ(counts.inside_tiles, in_memory.inside_tiles);
        EXPECT_EQ(counts.bytes, in_memory.bytes);
        EXPECT_EQ(counts.leaves, band.counts().active_blocks + band.counts().mixed_blocks);
        ASSERT_TRUE(fs::exists(path));
        // A band held in float32 (sdf-sample's float32 runs) writes the same file.
        BandChannels f32_channels;
        f32_channels.distance_type = BandDistanceType::Float32;
        const std::string f32_path = temp_path("band-f32.nvdb");
        fs::remove(f32_path);
        write_sparse_band_nvdb(
            make_cpu_bvh_sampler(options(c.sign, 0))->bind(share(c.mesh))->sample_band_sparse(lattice, w, f32_channels), f32_path);
        EXPECT_TRUE(file_bytes(f32_path) == file_bytes(path)) << "a float32 band's .nvdb differs from the double band's";
        fs::remove(f32_path);
        EXPECT_EQ(counts.active_voxels, band.counts().band_points);
        if (c.name.find("mixed") != std::string::npos) {
            EXPECT_GT(band.counts().mixed_blocks, 0);
        }
        EXPECT_GT(band.counts().inside_tiles, 0) << "the test should cover inside tiles";

        const std::vector<std::string> names =
            c.type == LatticeType::CC ? std::vector<std::string>{"distance"}
                                      : std::vector<std::string>{"distance_primary", "distance_secondary"};
        std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
        for (const std::string& name : names) handles.push_back(nanovdb::io::readGrid(path, name));
        std::vector<const nanovdb::NanoGrid<float>*> grids;
        uint64_t active = 0;
        for (size_t g = 0; g < handles.size(); ++g) {
            const nanovdb::NanoGrid<float>* grid = handles[g].grid<float>();
            ASSERT_NE(grid, nullptr) << names[g] << " is not a float grid";
            EXPECT_EQ(grid->gridClass(), nanovdb::GridClass::LevelSet);
            EXPECT_EQ(grid->tree().background(), float(w));
            EXPECT_EQ(std::string(grid->gridName()), names[g]);
            active += grid->activeVoxelCount();
            grids.push_back(grid);
        }
        EXPECT_EQ(int64_t(active), band.counts().band_points);

        int64_t wrong_value = 0, wrong_state = 0, in_band = 0;
        double worst_position = 0;
        for (int64_t i = 0; i < lattice.num_points(); ++i) {
            const auto [coset, ijk] = voxel_of(lattice, i);
            const auto acc = grids[size_t(coset)]->getAccessor();
            const float v = acc.getValue(ijk);
            const bool band_point = dense.closest_triangle[size_t(i)] != kOutsideBandTriangle;
            in_band += band_point;
            if (v != float(dense.distance[size_t(i)])) ++wrong_value;
            if (acc.isActive(ijk) != band_point) ++wrong_state;
            const nanovdb::Vec3d p = grids[size_t(coset)]->indexToWorld(nanovdb::Vec3d(ijk[0], ijk[1], ijk[2]));
            const Vec3d q = lattice.position(i);
            worst_position = std::max({worst_position, std::abs(p[0] - q.x), std::abs(p[1] - q.y), std::abs(p[2] - q.z)});
        }
        EXPECT_EQ(wrong_value, 0) << "of " << lattice.num_points() << " points";
        EXPECT_EQ(wrong_state, 0);
        EXPECT_GT(in_band, 0);
        EXPECT_LE(worst_position, 1e-12 * lattice.spacing * 64) << "the map is not the lattice's transform";

        // 10,000 random lattice points: the grid's side is the field's.
        std::mt19937_64 rng(7);
        std::uniform_int_distribution<int64_t> pick(0, lattice.num_points() - 1);
        int64_t wrong_sign = 0, inside = 0;
        for (int k = 0; k < 10000; ++k) {
            const int64_t i = pick(rng);
            const auto [coset, ijk] = voxel_of(lattice, i);
            const float v = grids[size_t(coset)]->getAccessor().getValue(ijk);
            const double d = dense.distance[size_t(i)];
            inside += d < 0;
            if ((v < 0) != (d < 0)) ++wrong_sign;
        }
        EXPECT_EQ(wrong_sign, 0);
        EXPECT_GT(inside, 0);

        // An existing file is refused, and no temporary is left beside it.
        EXPECT_THROW(write_sparse_band_nvdb(band, path), std::runtime_error);
        EXPECT_NO_THROW(write_sparse_band_nvdb(band, path, Overwrite::Allow));
        const std::string temporaries = "." + fs::path(path).filename().string() + ".tmp.";  // unique_sibling_name's
        int left = 0;
        for (const auto& e : fs::directory_iterator(fs::path(path).parent_path()))
            left += e.path().filename().string().rfind(temporaries, 0) == 0;
        EXPECT_EQ(left, 0);
        fs::remove(path);
    }
}

TEST(SparseNvdb, GridsSpanningManyNodesAreLaidOutAsNanoVdbsOwnConversion) {
    // A synthetic band on lattices long enough for several upper nodes (4096 points per axis)
    // and many lower nodes (128): random active, mixed and inside blocks, with padding on the
    // far edges, so that the node order, child offsets and tiles of every level are checked.
    for (const LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        SCOPED_TRACE(type == LatticeType::CC ? "CC" : "BCC");
        Lattice lattice;
        lattice.type = type;
        lattice.origin = {-1.5, 0.25, 3.0};
        lattice.spacing = 0.001;
        lattice.resolution = {4100 * 2 + 5, 260, 21};
        const double w = 3 * lattice.spacing;
        SparseBandField band(lattice, w, Precision::Double, BandChannels{false, false});
        std::mt19937_64 rng(11);
        std::uniform_real_distribution<double> value(-w, w);
        std::uniform_int_distribution<int> kind(0, 15);
        const BandLayout& layout = band.layout();
        for (int64_t id = 0; id < layout.block_count(); ++id) {
            const int k = kind(rng);
            if (k == 0) {
                const int64_t a = band.add_active(id);
                for (int local = 0; local < kBandBlockPoints; ++local) {
                    if (layout.storage_index(id, local) < 0) continue;
                    const double d = value(rng);
                    if (local % 3 == 0) {
                        band.distance.set(size_t(a) * kBandBlockPoints + size_t(local), d < 0 ? -w : w);  // outside the band
                    } else {
                        band.distance.set(size_t(a) * kBandBlockPoints + size_t(local), d);
                        set_mask_bit(band.band_mask[size_t(a)], local);
                    }
                }
            } else if (k == 1) {
                const int64_t m = band.add_mixed(id);
                for (int local = 0; local < kBandBlockPoints; ++local)
                    if (layout.storage_index(id, local) >= 0 && value(rng) < 0) set_mask_bit(band.mixed_inside[size_t(m)], local);
            }
            if (k >= 1 && k <= 6) band.set_tile_inside(id, true);  // on a mixed block: ignored (it is a leaf)
        }
        SparseNvdbCounts counts;
        const auto built = sparse_band_nanogrids(band, &counts);
        expect_nanovdbs_own_grids(built, reference_grids(band));
        uint64_t uppers = 0, lowers = 0;
        for (const auto& handle : built) {
            uppers += handle.grid<float>()->tree().nodeCount(2);
            lowers += handle.grid<float>()->tree().nodeCount(1);
        }
        EXPECT_GE(uppers, uint64_t(3 * built.size())) << "the lattice should span several upper nodes";
        EXPECT_GE(lowers, uint64_t(100));
        EXPECT_EQ(counts.active_voxels, band.counts().band_points);
        EXPECT_EQ(counts.inside_tiles, band.counts().inside_tiles);
        EXPECT_EQ(counts.leaves, band.counts().active_blocks + band.counts().mixed_blocks);

        const std::string path = temp_path("many_nodes.nvdb");
        fs::remove(path);
        const SparseNvdbCounts written = write_sparse_band_nvdb(band, path);
        EXPECT_TRUE(file_bytes(path) == nanovdb_file_bytes(built)) << "the streamed file differs from io::writeGrids'";
        EXPECT_EQ(written.bytes, counts.bytes);
        // Through many windows (one lower node's 4096 leaves each, at least): the same bytes.
        write_sparse_band_nvdb_windows(band, path, Overwrite::Allow, 1);
        EXPECT_TRUE(file_bytes(path) == nanovdb_file_bytes(built)) << "streamed through small windows";
        fs::remove(path);
    }
}

Lattice long_lattice(LatticeType type) {
    Lattice lattice;
    lattice.type = type;
    lattice.origin = {-1.5, 0.25, 3.0};
    lattice.spacing = 0.001;
    lattice.resolution = {600, 40, 21};
    return lattice;
}

TEST(SparseNvdb, EmptyAndLeaflessGridsAreNanoVdbsOwn) {
    // No block at all; inside tiles only (lower nodes without leaves); a BCC band whose
    // secondary grid is empty; the last, padded block alone.
    for (const LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        SCOPED_TRACE(type == LatticeType::CC ? "CC" : "BCC");
        const Lattice lattice = long_lattice(type);
        const double w = 2 * lattice.spacing;
        std::vector<SparseBandField> bands(4, SparseBandField(lattice, w, Precision::Double, BandChannels{false, false}));
        const BandLayout& layout = bands[0].layout();
        for (int64_t id = 0; id < layout.block_count(); id += 7) bands[1].set_tile_inside(id, true);
        const int64_t primary_blocks = layout.coset(0).blocks.x * int64_t(layout.coset(0).blocks.y) * layout.coset(0).blocks.z;
        const int64_t a = bands[2].add_active(primary_blocks / 2);  // the primary grid's middle block
        for (int local = 0; local < kBandBlockPoints; local += 3) {
            bands[2].distance.set(size_t(a) * kBandBlockPoints + size_t(local), 0.25 * w);
            set_mask_bit(bands[2].band_mask[size_t(a)], local);
        }
        const int64_t last = bands[3].add_active(primary_blocks - 1);  // padded on every axis
        for (int local = 0; local < kBandBlockPoints; ++local)
            if (layout.storage_index(primary_blocks - 1, local) >= 0) {
                bands[3].distance.set(size_t(last) * kBandBlockPoints + size_t(local), -0.5 * w);
                set_mask_bit(bands[3].band_mask[size_t(last)], local);
            }
        for (size_t i = 0; i < bands.size(); ++i) {
            SCOPED_TRACE("band " + std::to_string(i));
            const auto built = sparse_band_nanogrids(bands[i]);
            expect_nanovdbs_own_grids(built, reference_grids(bands[i]));
            const std::string path = temp_path("edge.nvdb");
            fs::remove(path);
            write_sparse_band_nvdb_windows(bands[i], path, Overwrite::Forbid, 1);
            EXPECT_TRUE(file_bytes(path) == nanovdb_file_bytes(built));
            fs::remove(path);
        }
    }
}

TEST(SparseNvdb, BandsThatDoNotMatchTheirBlocksAreRefused) {
    const Lattice lattice = long_lattice(LatticeType::CC);
    SparseBandField band(lattice, 2 * lattice.spacing, Precision::Double, BandChannels{false, false});
    band.add_active(3);
    band.add_mixed(5);
    const std::string path = temp_path("refused.nvdb");
    fs::remove(path);
    const auto refused = [&](SparseBandField b, const std::string& expected) {
        SCOPED_TRACE(expected);
        try {
            sparse_band_nanogrids(b);
            ADD_FAILURE() << "in memory: not refused";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
        }
        EXPECT_THROW(write_sparse_band_nvdb(b, path), std::invalid_argument);
        EXPECT_FALSE(fs::exists(path));
    };
    SparseBandField b = band;
    b.distance.resize(10);
    refused(b, "value arrays");
    b = band;
    b.inside_tiles.clear();
    refused(b, "tile signs");
    b = band;
    b.mixed_inside.clear();
    refused(b, "sign masks");
    b = band;
    b.active[0] = band.layout().block_count();
    refused(b, "must ascend");
    b = band;
    b.lattice.resolution.x += 64;
    refused(b, "not the one its blocks");
    b = band;
    b.active[0] = 5;  // also mixed
    b.mixed_inside.assign(1, BandSignMask{});
    try {
        sparse_band_nanogrids(b);
        ADD_FAILURE() << "a block both active and mixed was not refused";
    } catch (const std::logic_error& e) {
        EXPECT_NE(std::string(e.what()).find("twice"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace sdf
