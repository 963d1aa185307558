// The sparse band's NanoVDB level set (harness/io/sparse_nvdb_file.h, issue 35) read back by
// NanoVDB's own reader (io::readGrid): at every lattice point, CC and BCC, the grid's value is
// the dense banded field's float value (exact within the band, +-W outside it with its side,
// inside tiles included) and its voxel is active exactly where the point is within the band;
// the grids are level sets with background W, named as the .vdb's, and each grid's map puts
// its voxel (i, j, k) at the lattice point's own position. 10,000 random lattice points agree
// in sign with the field. Built only where NanoVDB's headers are found (cmake/Dependencies.cmake).
#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/io/IO.h>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "harness/io/sparse_nvdb_file.h"
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
        const SparseNvdbCounts counts = write_sparse_band_nvdb(band, path);
        ASSERT_TRUE(fs::exists(path));
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

}  // namespace
}  // namespace sdf
