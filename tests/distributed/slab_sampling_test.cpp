// Slabs (kernels/lattice/lattice_slab.h) and their plans (harness/sampling/slab_plan.h):
// the slabs of a plan tile the lattice, and every sampler's samples of a slab are the whole
// lattice's samples at the slab's storage offsets, bit for bit. This is what makes a
// distributed run's field files equal a single process's (tests/distributed/mpi_runs.sh
// checks the files themselves under mpirun).
#include <gtest/gtest.h>

#include <cstring>
#include <numeric>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "harness/sampling/slab_plan.h"
#include "harness/sampling/sampler_table.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

PreparedMesh test_mesh() { return prepare_mesh(make_torus(1.0, 0.35, 24, 12)); }

std::vector<Lattice> test_lattices(const PreparedMesh& mesh) {
    return {fit_lattice(LatticeType::CC, {11, 9, 13}, mesh.bounds(), 0.1),
            fit_lattice(LatticeType::BCC, {8, 7, 9}, mesh.bounds(), 0.1)};
}

/// The slab's samples equal the whole field's at the slab's offsets, byte for byte.
void expect_same_samples(const SampledField& whole, const SampledField& part, const Lattice& lattice,
                         const LatticeSlab& slab, const std::string& what) {
    ASSERT_EQ(part.size(), slab_point_count(lattice, slab)) << what;
    int64_t from = 0;
    for (int p = 0; p < 2; ++p) {
        const StorageRange r = slab_storage(lattice, slab, p);
        const size_t n = size_t(r.count), at = size_t(r.offset), f = size_t(from);
        EXPECT_EQ(0, std::memcmp(part.distance.data() + f, whole.distance.data() + at, n * sizeof(double))) << what << " part " << p;
        EXPECT_EQ(0, std::memcmp(part.gradient.data() + f, whole.gradient.data() + at, n * sizeof(Vec3d))) << what << " part " << p;
        EXPECT_EQ(0, std::memcmp(part.closest_triangle.data() + f, whole.closest_triangle.data() + at, n * sizeof(int32_t)))
            << what << " part " << p;
        from += r.count;
    }
}

TEST(LatticeSlab, SlabsOfAPlanTileEveryPointOnce) {
    const PreparedMesh mesh = test_mesh();
    for (const Lattice& lattice : test_lattices(mesh))
        for (int parts : {1, 2, 3, 5, 20}) {
            SamplerOptions o;
            o.backend = "cpu";
            o.method = "bvh";
            const SlabPlan plan = plan_slabs(mesh, lattice, o, parts);
            ASSERT_EQ(int(plan.slabs.size()), parts);
            std::vector<int> seen(size_t(lattice.num_points()), 0);
            int next_plane = 0;
            for (const LatticeSlab& s : plan.slabs) {
                EXPECT_EQ(s.z_begin, next_plane);
                next_plane = s.z_end;
                for (int p = 0; p < 2; ++p) {
                    const StorageRange r = slab_storage(lattice, s, p);
                    for (int64_t i = r.offset; i < r.offset + r.count; ++i) ++seen[size_t(i)];
                }
            }
            EXPECT_EQ(next_plane, lattice.resolution.z);
            EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), lattice.num_points()) << parts << " parts";
            if (parts <= lattice.resolution.z) {
                for (const LatticeSlab& s : plan.slabs) EXPECT_LT(s.z_begin, s.z_end);
            }
            EXPECT_EQ(plan.estimate, "bvh_visits");
            EXPECT_GE(plan.estimated_max_over_mean(), 1.0);
        }
}

TEST(LatticeSlab, BalancedSlabsFollowTheCost) {
    // One expensive plane in the middle: it gets a slab of its own.
    const std::vector<double> cost = {1, 1, 1, 1, 20, 1, 1, 1, 1, 1};
    const std::vector<LatticeSlab> s = balanced_slabs(cost, 3);
    ASSERT_EQ(s.size(), 3u);
    EXPECT_EQ(s[0].z_begin, 0);
    EXPECT_EQ(s[2].z_end, 10);
    EXPECT_LE(s[0].z_end, 4);   // the cheap planes before it
    EXPECT_GE(s[1].z_end, 5);   // the expensive plane
    // Uniform cost: equal thirds (to a plane).
    const std::vector<LatticeSlab> u = balanced_slabs(std::vector<double>(9, 1.0), 3);
    EXPECT_EQ(u[0].z_end, 3);
    EXPECT_EQ(u[1].z_end, 6);
    // More parts than planes: every plane once, the rest empty.
    const std::vector<LatticeSlab> m = balanced_slabs(std::vector<double>(2, 1.0), 4);
    int planes = 0;
    for (const LatticeSlab& x : m) planes += x.z_end - x.z_begin;
    EXPECT_EQ(planes, 2);
}

TEST(LatticeSlab, EverySamplerSamplesASlabAsTheWholeLattice) {
    const PreparedMesh mesh = test_mesh();
    for (const SamplerKind& kind : sampler_table()) {
        if (std::string(kind.backend) != "cpu") continue;
        for (const std::string& kernel : kind.kernels)
            for (Precision precision : {Precision::Float, Precision::Double})
                for (BccStrategy strategy : {BccStrategy::TwoGrids, BccStrategy::DoubleResolution}) {
                    SamplerOptions o;
                    o.backend = kind.backend;
                    o.method = kind.method;
                    o.kernel = kernel;
                    o.precision = precision;
                    o.bcc_strategy = strategy;
                    o.threads = 2;
                    o.progress = false;
                    const auto sampler = make_sampler(o);
                    for (const Lattice& lattice : test_lattices(mesh)) {
                        const SampledField whole = sampler->bind(share(mesh))->sample(lattice);
                        // Cuts at every plane count from one to all, and a balanced plan.
                        std::vector<LatticeSlab> slabs;
                        for (int z = 0; z < lattice.resolution.z; ++z) slabs.push_back({z, std::min(lattice.resolution.z, z + 1 + z % 3)});
                        for (const LatticeSlab& s : plan_slabs(mesh, lattice, o, 3).slabs) slabs.push_back(s);
                        for (const LatticeSlab& s : slabs) {
                            const std::string what = sampler->name() + " " + precision_name(precision) + " " +
                                                     bcc_strategy_name(strategy) + " " + lattice_notation(lattice) +
                                                     " planes [" + std::to_string(s.z_begin) + ", " + std::to_string(s.z_end) + ")";
                            expect_same_samples(whole, sampler->bind(share(mesh))->sample_slab(lattice, s), lattice, s, what);
                        }
                    }
                }
    }
}

}  // namespace
}  // namespace sdf
