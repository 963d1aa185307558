// The CPU BVH sampler equals the CPU brute-force sampler on every test mesh (sphere, box,
// torus, pawn, soccer ball, a sphere of tiny and sliver triangles, a slab of large flat
// faces, bunny and dragon when present), on CC and BCC lattices and random points, in float
// and double: the same triangle gives the same distance, sign and gradient to 1e-12; any
// other triangle must be a tie (checked with the exact distances to both).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/bvh/bvh_cpu_points.h"
#include "core/lattice/lattice_fitting.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "kernels/core/morton.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

SamplerOptions options(Precision precision, const std::string& kernel = "", int threads = 0,
                       BccStrategy strategy = BccStrategy::TwoGrids) {
    SamplerOptions o;
    o.precision = precision;
    o.kernel = kernel;
    o.threads = threads;
    o.bcc_strategy = strategy;
    o.progress = false;
    return o;
}

std::vector<Vec3d> random_points_around(const PreparedMesh& mesh, int n, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-0.75, 0.75);
    const Vec3d c = mesh.bounds().center(), e = mesh.bounds().extent();
    std::vector<Vec3d> pts(static_cast<size_t>(n));
    for (auto& p : pts) p = c + component_mul(e, Vec3d{u(rng), u(rng), u(rng)});
    return pts;
}

void print(const std::string& what, const test::Agreement& a, const PreparedMesh& mesh) {
    std::printf("%-40s %7lld points: max|dd| = %.3g (%.2g of diag), triangle ties %lld, sign ties %lld\n", what.c_str(),
                (long long)a.points, a.max_abs_distance, a.max_abs_distance / mesh.bounds().diagonal(),
                (long long)a.triangle_ties, (long long)a.sign_ties);
}

TEST(CpuBvh, EqualsBruteForceOnLatticesOfEveryMesh) {
    for (const test::NamedMesh& m : test::bvh_test_meshes()) {
        const bool big = m.mesh.triangles().size() > 20000;
        for (Precision precision : {Precision::Float, Precision::Double}) {
            // Brute force in double on 100k triangles is the slow part: smaller lattices there.
            const int r = big ? (precision == Precision::Double ? 10 : 14) : 24;
            const Lattice cc = fit_lattice(LatticeType::CC, {r, r + 1, r + 2}, m.mesh.bounds(), 0.1);
            const Lattice bcc = fit_lattice(LatticeType::BCC, {r - 3, r - 2, r - 1}, m.mesh.bounds(), 0.1);
            for (const Lattice& lattice : {cc, bcc}) {
                const SampledField brute = make_cpu_brute_force_sampler(options(precision))->bind(share(m.mesh))->sample(lattice);
                const SampledField bvh = make_cpu_bvh_sampler(options(precision))->bind(share(m.mesh))->sample(lattice);
                test::FieldComparer cmp(m.mesh, test::epsilon_of(precision));
                const std::string what = m.name + " " + lattice_notation(lattice) + " " + precision_name(precision);
                cmp.fields(brute, bvh, what);
                if (HasFatalFailure()) return;
                print(what, cmp.agreement(), m.mesh);
                EXPECT_EQ(bvh.sampler.method, "bvh");
            }
        }
    }
}

TEST(CpuBvh, EqualsBruteForceOnRandomPoints) {
    for (const test::NamedMesh& m : test::bvh_test_meshes()) {
        const bool big = m.mesh.triangles().size() > 20000;
        const auto pts = random_points_around(m.mesh, big ? 1500 : 5000, 17);
        for (Precision precision : {Precision::Float, Precision::Double}) {
            if (big && precision == Precision::Double) continue;  // covered on lattices above
            const auto brute = make_cpu_brute_force_sampler(options(precision))->bind(share(m.mesh))->query(pts);
            for (const char* kernel : {"brick", "seeded", "unseeded"}) {
                const auto bvh = make_cpu_bvh_sampler(options(precision, kernel))->bind(share(m.mesh))->query(pts);
                test::FieldComparer cmp(m.mesh, test::epsilon_of(precision));
                const std::string what = m.name + " random " + precision_name(precision) + " " + kernel;
                cmp.samples(pts, brute, bvh, what);
                if (HasFatalFailure()) return;
                print(what, cmp.agreement(), m.mesh);
            }
        }
    }
}

/// Points drawn as neural-SDF training generators draw them: an area-weighted random
/// triangle, a uniform point on it, and a Gaussian offset of `sigma` per axis.
std::vector<Vec3d> gaussian_points_near_surface(const PreparedMesh& mesh, int n, double sigma, unsigned seed) {
    std::vector<double> area;
    for (const Int3& t : mesh.triangles()) {
        const Vec3d a = mesh.vertices()[size_t(t.x)], b = mesh.vertices()[size_t(t.y)], c = mesh.vertices()[size_t(t.z)];
        area.push_back(0.5 * length(cross(b - a, c - a)));
    }
    std::mt19937_64 rng(seed);
    std::discrete_distribution<size_t> pick(area.begin(), area.end());
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::normal_distribution<double> offset(0.0, sigma);
    std::vector<Vec3d> pts(static_cast<size_t>(n));
    for (auto& p : pts) {
        const Int3 t = mesh.triangles()[pick(rng)];
        double s = u(rng), r = u(rng);
        if (s + r > 1) s = 1 - s, r = 1 - r;
        const Vec3d a = mesh.vertices()[size_t(t.x)], b = mesh.vertices()[size_t(t.y)], c = mesh.vertices()[size_t(t.z)];
        p = a + (b - a) * s + (c - a) * r + Vec3d{offset(rng), offset(rng), offset(rng)};
    }
    return pts;
}

void expect_identical(const std::vector<PointSample>& a, const std::vector<PointSample>& b, const std::string& what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    int64_t differing = 0;
    for (size_t i = 0; i < a.size(); ++i)
        differing += a[i].distance != b[i].distance || a[i].triangle != b[i].triangle || a[i].gradient.x != b[i].gradient.x ||
                     a[i].gradient.y != b[i].gradient.y || a[i].gradient.z != b[i].gradient.z;
    EXPECT_EQ(differing, 0) << what << ": samples that differ from the per-point query";
}

// The Morton packet query ("brick" on point lists) returns the per-point query's samples bit
// for bit (same triangle by the same tie rule, same double evaluation), in input order, on
// uniform and Gaussian-near-surface point sets, at any thread count; and both equal brute force.
TEST(CpuBvh, MortonPacketQueryEqualsPerPointQueryBitForBit) {
    const auto& meshes = test::bvh_test_meshes();
    for (const size_t which : {size_t(3), size_t(5)}) {  // pawn; a sphere of tiny and sliver triangles
        const PreparedMesh& mesh = meshes[which].mesh;
        const double diag = mesh.bounds().diagonal();
        for (int set = 0; set < 2; ++set) {
            const auto pts = set == 0 ? random_points_around(mesh, 3001, 5) : gaussian_points_near_surface(mesh, 3001, 0.01 * diag, 6);
            const std::string what = meshes[which].name + (set == 0 ? " uniform" : " gaussian");
            for (Precision precision : {Precision::Float, Precision::Double}) {
                const auto seeded = make_cpu_bvh_sampler(options(precision, "seeded", 1))->bind(share(mesh))->query(pts);
                const auto packets = make_cpu_bvh_sampler(options(precision, "brick", 2))->bind(share(mesh))->query(pts);
                expect_identical(seeded, packets, what + " " + precision_name(precision));
                const auto one_thread = make_cpu_bvh_sampler(options(precision, "brick", 1))->bind(share(mesh))->query(pts);
                expect_identical(one_thread, packets, what + " 1 vs 2 threads");
                const auto brute = make_cpu_brute_force_sampler(options(precision))->bind(share(mesh))->query(pts);
                test::FieldComparer cmp(mesh, test::epsilon_of(precision));
                cmp.samples(pts, brute, packets, what + " packets vs brute force");
                if (HasFatalFailure()) return;
            }
        }
    }
}

/// The Morton order of the packets, sorted in parallel: on 1, 2 and 7 threads the order a
/// plain sort of (key, index) gives, on 300,000 points (five chunks of the sort) with
/// repeated points (equal keys, kept in input order).
TEST(CpuBvh, MortonOrderIsTheSortedOrderOnEveryThreadCount) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-2.0, 5.0);
    std::vector<Vec3d> points(300000);
    for (size_t i = 0; i < points.size(); ++i) points[i] = i % 5 == 4 ? points[i - 3] : Vec3d{u(rng), u(rng), u(rng)};
    Vec3d lo = points[0], hi = points[0];
    for (const Vec3d& p : points) {
        lo = component_min(lo, p);
        hi = component_max(hi, p);
    }
    const double inv_extent = 1.0 / std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    std::vector<std::pair<uint64_t, uint32_t>> keyed(points.size());
    for (size_t i = 0; i < points.size(); ++i)
        keyed[i] = {morton_key_of_point(points[i].x, points[i].y, points[i].z, lo.x, lo.y, lo.z, inv_extent) >> 33, uint32_t(i)};
    std::sort(keyed.begin(), keyed.end());
    std::vector<uint32_t> want(points.size());
    for (size_t i = 0; i < keyed.size(); ++i) want[i] = keyed[i].second;
    // The same points as the caller's arrays: every other column of an N x 6 array.
    std::vector<double> columns(6 * points.size(), -7.0);
    for (size_t i = 0; i < points.size(); ++i)
        for (int k = 0; k < 3; ++k) columns[6 * i + 2 * size_t(k)] = points[i][k];
    const HostPoints strided{columns.data(), false, int64_t(points.size()), 6, 2};
    for (int threads : {1, 2, 7}) {
        EXPECT_EQ(cpu_bvh::morton_order(points, threads), want) << threads << " threads";
        EXPECT_EQ(cpu_bvh::morton_order(strided, threads), want) << threads << " threads, strided";
    }
    EXPECT_TRUE(cpu_bvh::morton_order(std::vector<Vec3d>{}, 2).empty());
}

TEST(CpuBvh, BccDoubleResolutionStrategyAndThreadCountsGiveTheSameField) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[4].mesh;  // soccer ball
    const Lattice lattice = fit_lattice(LatticeType::BCC, {17, 18, 19}, mesh.bounds(), 0.1);
    const SampledField two = make_cpu_bvh_sampler(options(Precision::Float, "", 1))->bind(share(mesh))->sample(lattice);
    const SampledField two_threads = make_cpu_bvh_sampler(options(Precision::Float, "", 2))->bind(share(mesh))->sample(lattice);
    const SampledField doubled =
        make_cpu_bvh_sampler(options(Precision::Float, "", 0, BccStrategy::DoubleResolution))->bind(share(mesh))->sample(lattice);
    EXPECT_EQ(two.distance, two_threads.distance);
    EXPECT_EQ(two.closest_triangle, two_threads.closest_triangle);
    // Strategy A sees the same points in another order (other seeds): equal up to ties.
    test::FieldComparer cmp(mesh, test::epsilon_of(Precision::Float));
    cmp.fields(two, doubled, "soccer ball BCC strategies");
}

double work_seeded_or_zero(const SampledField& f) { return f.sampler.details.at("bvh")["node_visits_per_point"].get<double>(); }

TEST(CpuBvh, BrickSeededAndUnseededKernelsAgreeAndCoherenceSavesWork) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[3].mesh;  // pawn
    const Lattice lattice = fit_lattice(LatticeType::CC, {32, 32, 32}, mesh.bounds(), 0.1);
    const SampledField seeded = make_cpu_bvh_sampler(options(Precision::Float, "seeded"))->bind(share(mesh))->sample(lattice);
    const SampledField unseeded = make_cpu_bvh_sampler(options(Precision::Float, "unseeded"))->bind(share(mesh))->sample(lattice);
    test::FieldComparer cmp(mesh, test::epsilon_of(Precision::Float));
    cmp.fields(unseeded, seeded, "pawn seeded vs unseeded");
    const SampledField brick = make_cpu_bvh_sampler(options(Precision::Float, "brick"))->bind(share(mesh))->sample(lattice);
    test::FieldComparer cmp_brick(mesh, test::epsilon_of(Precision::Float));
    cmp_brick.fields(unseeded, brick, "pawn brick vs unseeded");
    EXPECT_LT(brick.sampler.details.at("bvh")["node_visits_per_point"].get<double>(), work_seeded_or_zero(seeded));
    const double work_seeded = seeded.sampler.details.at("bvh")["node_visits_per_point"].get<double>();
    const double work_unseeded = unseeded.sampler.details.at("bvh")["node_visits_per_point"].get<double>();
    std::printf("pawn 32^3: node visits per point %.2f seeded, %.2f unseeded\n", work_seeded, work_unseeded);
    EXPECT_LT(work_seeded, work_unseeded);
}

TEST(CpuBvh, RejectsUnknownKernelsByName) {
    try {
        make_cpu_bvh_sampler(options(Precision::Float, "vectorized"));
        FAIL() << "a brute-force kernel name must be rejected";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("vectorized"), std::string::npos);
    }
}

}  // namespace
}  // namespace sdf
