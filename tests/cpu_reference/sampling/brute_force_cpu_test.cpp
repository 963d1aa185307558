// The CPU brute-force sampler against independent truth: analytic signed distances of the
// box, sphere and torus, a ray-parity inside test for the pawn and soccer ball, central
// differences for gradients; and its own invariants (BCC strategies, threads, precision).
#include <gtest/gtest.h>

#include <random>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/parallel/progress.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "kernels/distance/closest_point_on_triangle.h"
#include "tests/cpu_reference/sampling/analytic_shapes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

std::vector<Vec3d> random_points(int n, double extent, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-extent, extent);
    std::vector<Vec3d> p(static_cast<size_t>(n));
    for (auto& q : p) q = {u(rng), u(rng), u(rng)};
    return p;
}

std::vector<PointSample> query(const PreparedMesh& mesh, const std::vector<Vec3d>& pts, Precision precision,
                               int threads = 0, const std::string& kernel = "") {
    SamplerOptions o;
    o.precision = precision;
    o.threads = threads;
    o.kernel = kernel;
    o.progress = false;
    return make_cpu_brute_force_sampler(o)->bind(share(mesh))->query(pts);
}

/// Largest gap between an icosphere mesh and its sphere: r minus the smallest distance from
/// the centre to a triangle plane (every triangle's vertices lie on the sphere).
double icosphere_chord_error(const TriangleMesh& m, double r) {
    double nearest = r;
    for (const Int3& t : m.triangles) {
        const Vec3d a = m.vertices[size_t(t.x)], b = m.vertices[size_t(t.y)], c = m.vertices[size_t(t.z)];
        nearest = std::min(nearest, std::abs(dot(normalize_or_zero(cross(b - a, c - a)), a)));
    }
    return r - nearest;
}

TEST(CpuBruteForce, BoxDistancesAreExactIncludingEdgesAndCorners) {
    const Vec3d half{1.0, 0.5, 0.75};
    const PreparedMesh box = prepare_mesh(make_box(half));
    std::vector<Vec3d> pts = random_points(20000, 2.0, 1);
    // Points whose nearest feature is an edge or a corner, inside and outside.
    for (double s : {-1.0, 1.0})
        for (double t : {-1.0, 1.0}) {
            pts.push_back({s * 1.3, t * 0.9, 0.1});    // nearest: an edge parallel to z
            pts.push_back({s * 1.2, t * 0.7, 1.1});    // nearest: a corner
            pts.push_back({s * 0.999, t * 0.499, 0.0});  // just inside, near an edge
        }
    const auto d64 = query(box, pts, Precision::Double);
    const auto d32 = query(box, pts, Precision::Float);
    for (size_t i = 0; i < pts.size(); ++i) {
        const double truth = test::box_sdf(pts[i], half);
        ASSERT_NEAR(d64[i].distance, truth, 1e-12 * std::max(1.0, std::abs(truth))) << i;
        // Float: relative to the distance, with the box's own size as the floor (the float
        // coordinates themselves carry ~6e-8 of it).
        ASSERT_NEAR(d32[i].distance, truth, 1e-6 * std::max(1.0, std::abs(truth))) << i;
        ASSERT_GE(d64[i].triangle, 0);
        ASSERT_LT(d64[i].triangle, 12);
    }
}

TEST(CpuBruteForce, SphereWithinChordError) {
    for (int sub : {3, 4}) {
        const TriangleMesh raw = make_icosphere(sub, 1.0);
        const double bound = icosphere_chord_error(raw, 1.0);
        const PreparedMesh sphere = prepare_mesh(raw);
        const auto pts = random_points(5000, 2.0, 2 + unsigned(sub));
        const auto d = query(sphere, pts, Precision::Double);
        for (size_t i = 0; i < pts.size(); ++i)
            ASSERT_NEAR(d[i].distance, test::sphere_sdf(pts[i], 1.0), bound * (1 + 1e-9)) << "sub " << sub;
    }
}

TEST(CpuBruteForce, TorusWithinChordError) {
    const double R = 1.0, r = 0.35;
    const int M = 48, N = 24;
    const PreparedMesh torus = prepare_mesh(make_torus(R, r, M, N));
    // Every mesh point is within the sagittas of the two tessellation directions of the torus.
    const double pi = 3.14159265358979323846;
    const double bound = (R + r) * (1 - std::cos(pi / M)) + r * (1 - std::cos(pi / N));
    const auto pts = random_points(5000, 1.6, 5);
    const auto d = query(torus, pts, Precision::Double);
    double worst = 0;
    for (size_t i = 0; i < pts.size(); ++i) worst = std::max(worst, std::abs(d[i].distance - test::torus_sdf(pts[i], R, r)));
    EXPECT_LE(worst, 2 * bound);
    std::printf("torus: worst |d_mesh - d_analytic| = %.3g, sagitta bound %.3g\n", worst, bound);
}

/// 10^5 random points around a closed shape: the sign agrees with independent truth for
/// every point farther from the surface than `ambiguous`.
template <typename Truth>
void expect_signs(const PreparedMesh& mesh, double extent, double ambiguous, Truth inside) {
    const auto pts = random_points(100000, extent, 7);
    const auto d = query(mesh, pts, Precision::Float);
    int checked = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        if (std::abs(d[i].distance) <= ambiguous) continue;
        ++checked;
        ASSERT_EQ(d[i].distance < 0, inside(pts[i])) << mesh.name() << " point " << i << " d=" << d[i].distance;
    }
    EXPECT_GT(checked, 98000) << mesh.name();  // at most 2% of the points lie in the ambiguous shell
}

TEST(CpuBruteForce, SignsOfAnalyticShapes) {
    const PreparedMesh box = prepare_mesh(make_box({1, 0.5, 0.75}));
    expect_signs(box, 1.5, 1e-6, [](const Vec3d& p) { return test::box_sdf(p, {1, 0.5, 0.75}) < 0; });
    const TriangleMesh ico = make_icosphere(4);
    const double chord = icosphere_chord_error(ico, 1.0);
    expect_signs(prepare_mesh(ico), 1.5, chord, [](const Vec3d& p) { return length(p) < 1.0; });
    // Torus: exclude twice the sagitta bound of TorusWithinChordError (~0.012) around the surface.
    expect_signs(prepare_mesh(make_torus(1.0, 0.35, 48, 24)), 1.5, 0.012,
                 [](const Vec3d& p) { return test::torus_sdf(p, 1.0, 0.35) < 0; });
}

TEST(CpuBruteForce, SignsOfPawnAndSoccerBallAgreeWithRayParity) {
    for (const TriangleMesh& raw : {make_pawn(), make_soccer_ball()}) {
        const PreparedMesh mesh = prepare_mesh(raw);
        const Vec3d c = mesh.bounds().center();
        const double extent = 0.7 * length(mesh.bounds().extent());
        // Ray parity is exact away from the surface (O(points x triangles): a few seconds).
        std::mt19937_64 rng(11);
        std::uniform_real_distribution<double> u(-extent, extent);
        std::vector<Vec3d> pts(100000);
        for (auto& p : pts) p = c + Vec3d{u(rng), u(rng), u(rng)};
        const auto d = query(mesh, pts, Precision::Float);
        int checked = 0;
        for (size_t i = 0; i < pts.size(); ++i) {
            if (std::abs(d[i].distance) < 1e-4) continue;
            ++checked;
            ASSERT_EQ(d[i].distance < 0, test::inside_by_ray_parity(pts[i], mesh.vertices(), mesh.triangles()))
                << mesh.name() << " point " << i;
        }
        EXPECT_GT(checked, 99500);
    }
}

TEST(CpuBruteForce, GradientsAreUnitAndMatchCentralDifferences) {
    const PreparedMesh mesh = prepare_mesh(make_pawn());
    const Vec3d c = mesh.bounds().center();
    auto pts = random_points(2000, 0.6, 9);
    for (auto& p : pts) p += c;
    const double h = 1e-6;
    std::vector<Vec3d> probes;
    for (const Vec3d& p : pts)
        for (int a = 0; a < 3; ++a)
            for (double s : {-1.0, 1.0}) {
                Vec3d q = p;
                q[a] += s * h;
                probes.push_back(q);
            }
    const auto d = query(mesh, pts, Precision::Double);
    const auto dp = query(mesh, probes, Precision::Double);
    int compared = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        ASSERT_NEAR(length(d[i].gradient), 1.0, 1e-12);
        Vec3d fd;
        for (int a = 0; a < 3; ++a) fd[a] = (dp[6 * i + 2 * a + 1].distance - dp[6 * i + 2 * a].distance) / (2 * h);
        // Across the medial axis the field has a kink and |fd| < 1: not a point to compare.
        if (std::abs(length(fd) - 1.0) > 1e-4) continue;
        ++compared;
        EXPECT_NEAR(length(fd - d[i].gradient), 0.0, 1e-5) << i;
    }
    EXPECT_GT(compared, int(0.95 * pts.size()));
}

TEST(CpuBruteForce, BccStrategiesGiveIdenticalFields) {
    const PreparedMesh mesh = prepare_mesh(make_soccer_ball(0));
    const Lattice lattice = fit_lattice(LatticeType::BCC, {11, 12, 10}, mesh.bounds(), 0.1);
    SamplerOptions o;
    o.progress = false;
    o.bcc_strategy = BccStrategy::TwoGrids;
    const SampledField b = make_cpu_brute_force_sampler(o)->bind(share(mesh))->sample(lattice);
    o.bcc_strategy = BccStrategy::DoubleResolution;
    const SampledField a = make_cpu_brute_force_sampler(o)->bind(share(mesh))->sample(lattice);
    ASSERT_EQ(a.size(), lattice.num_points());
    EXPECT_EQ(a.distance, b.distance);
    EXPECT_EQ(a.gradient, b.gradient);
    EXPECT_EQ(a.closest_triangle, b.closest_triangle);
    // Strategy A computes the 2x-resolution CC grid: 8 R^3 points, most discarded.
    EXPECT_EQ(a.sampler.points_computed, 8 * 11 * 12 * 10);
    EXPECT_EQ(b.sampler.points_computed, lattice.num_points());
}

TEST(CpuBruteForce, OneThreadAndManyThreadsAreBitIdentical) {
    const PreparedMesh mesh = prepare_mesh(make_pawn());
    const Lattice lattice = fit_lattice(LatticeType::CC, {14, 15, 16}, mesh.bounds(), 0.1);
    SamplerOptions o;
    o.progress = false;
    o.threads = 1;
    const SampledField one = make_cpu_brute_force_sampler(o)->bind(share(mesh))->sample(lattice);
    o.threads = 5;
    const SampledField many = make_cpu_brute_force_sampler(o)->bind(share(mesh))->sample(lattice);
    EXPECT_EQ(one.distance, many.distance);
    EXPECT_EQ(one.gradient, many.gradient);
    EXPECT_EQ(one.closest_triangle, many.closest_triangle);
}

/// Distance from p to one triangle of the prepared mesh, in double (for tie checks).
double distance_to_triangle(const PreparedMesh& m, const Vec3d& p, int tri) {
    const Int3 t = m.triangles()[size_t(tri)];
    return std::sqrt(closest_point_on_triangle(p, m.vertices()[size_t(t.x)], m.vertices()[size_t(t.y)],
                                               m.vertices()[size_t(t.z)]).distance_squared);
}

TEST(CpuBruteForce, FloatMatchesDoubleAndEberlyMatchesVectorized) {
    const PreparedMesh mesh = prepare_mesh(make_soccer_ball());
    ASSERT_EQ(mesh.source_triangle().back(), int(mesh.triangles().size()) - 1);  // file order = prepared order
    const double diag = mesh.bounds().diagonal();
    auto pts = random_points(3000, 0.8, 13);
    const auto d64 = query(mesh, pts, Precision::Double);
    const auto d32 = query(mesh, pts, Precision::Float);
    const auto e32 = query(mesh, pts, Precision::Float, 0, "eberly");
    int ties = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        // Relative to |d|, with 1% of the diagonal as the floor: float coordinates alone carry
        // an absolute error of ~6e-8 of the model size.
        const double scale = std::max(std::abs(d64[i].distance), 0.01 * diag);
        EXPECT_NEAR(d32[i].distance, d64[i].distance, 1e-5 * scale) << i;
        // The two float kernels search with different formulas, so near-ties may resolve to
        // different triangles; both answers are then exact to float resolution (~1e-7 here).
        EXPECT_NEAR(e32[i].distance, d32[i].distance, 1e-6 * std::max(std::abs(d64[i].distance), 0.1 * diag)) << i;
        if (d32[i].triangle != d64[i].triangle) {
            // A tie: the float's triangle is as near as the double's, to float resolution.
            ++ties;
            EXPECT_NEAR(distance_to_triangle(mesh, pts[i], d32[i].triangle), std::abs(d64[i].distance), 1e-5 * scale) << i;
            continue;
        }
        // The gradient is (P - C) / |P - C|: a float position error of ~1e-7 becomes a
        // direction error of ~1e-7 / |d|, so the tolerance grows below 1% of the diagonal.
        EXPECT_NEAR(length(d32[i].gradient - d64[i].gradient), 0.0, 1e-4 * scale / std::abs(d64[i].distance)) << i;
    }
    // Most "ties" are genuine: a closest point on an edge or vertex belongs to every triangle
    // around it, and either precision may name any of them.
    std::printf("float and double named different (equally near) triangles for %d of %zu points\n", ties, pts.size());
}

TEST(CpuBruteForce, OpenMeshIsSampledWithAWarning) {
    TriangleMesh open = make_box();
    open.triangles.pop_back();
    const PreparedMesh mesh = prepare_mesh(open);
    ASSERT_FALSE(mesh.warnings().empty());
    EXPECT_NE(mesh.warnings()[0].find("open"), std::string::npos);
    const auto d = query(mesh, {{0, 0, 3}, {0, 0, 0.5}}, Precision::Double);
    EXPECT_NEAR(d[0].distance, 2.0, 1e-12);    // distances stay exact
    EXPECT_NEAR(d[1].distance, -0.5, 1e-12);   // a point behind a closed part is "inside"
}

}  // namespace
}  // namespace sdf
