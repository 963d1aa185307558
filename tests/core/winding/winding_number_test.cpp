// Generalized winding numbers against independent truth: the solid angle of a known
// triangle; exact winding numbers of analytic shapes (sphere, box, torus) away from their
// surfaces; overlapping closed parts with a known union (two spheres and a box through
// them, the case the pseudonormal sign gets wrong); the fast evaluation against the exact
// sum (within the stated error bound everywhere, same sign wherever the bound decides);
// the certified sign against the pseudonormal sign of closed meshes and against the exact
// winding number of open and overlapping meshes; the auto choice of the sign mode.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "core/winding/winding_bvh.h"
#include "core/winding/winding_sign.h"
#include "kernels/winding/with_sign.h"
#include "tests/core/winding/mesh_parts.h"
#include "tests/cpu_reference/sampling/analytic_shapes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<Vec3d> random_points(int n, Vec3d lo, Vec3d hi, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Vec3d> p(size_t(n), Vec3d(0.0));
    for (Vec3d& q : p) q = {lo.x + (hi.x - lo.x) * u(rng), lo.y + (hi.y - lo.y) * u(rng), lo.z + (hi.z - lo.z) * u(rng)};
    return p;
}

/// Exact winding number of p over the prepared mesh (double MeshView, every triangle).
double exact_winding(const PreparedMesh& m, const Vec3d& p) { return winding_number_exact(m.buffers<double>().view(), p); }

TEST(SolidAngle, OctantTriangleSubtendsAnEighthOfTheSphere) {
    const Vec3d o{0, 0, 0}, x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};
    // Seen from the origin the triangle's counter-clockwise normal (1,1,1) points away: the
    // origin is behind it, on the inside side, so the angle is positive.
    EXPECT_NEAR(triangle_solid_angle(o, x, y, z), 4.0 * kPi / 8.0, 1e-15);
    EXPECT_NEAR(triangle_solid_angle(o, x, z, y), -4.0 * kPi / 8.0, 1e-15);
    EXPECT_EQ(triangle_solid_angle(Vec3d{3, 3, -5}, Vec3d{3, 4, -5}, Vec3d{4, 4, -5}, Vec3d{4, 3, -5}), 0.0);  // in its plane
}

// ---- Analytic shapes: w = 1 inside, 0 outside, away from the surface -------------------

struct AnalyticCase {
    const char* name;
    TriangleMesh mesh;
    double (*sdf)(const Vec3d&);
    double margin;  ///< more than the mesh's largest distance from the analytic surface
};

std::vector<AnalyticCase> analytic_cases() {
    return {{"sphere", make_icosphere(3, 1.0), [](const Vec3d& p) { return test::sphere_sdf(p, 1.0); }, 0.02},
            {"box", make_box({0.9, 0.5, 0.3}), [](const Vec3d& p) { return test::box_sdf(p, {0.9, 0.5, 0.3}); }, 1e-9},
            {"torus", make_torus(1.0, 0.35, 64, 32), [](const Vec3d& p) { return test::torus_sdf(p, 1.0, 0.35); }, 0.01}};
}

TEST(WindingNumber, AnalyticShapesAreOneInsideAndZeroOutside) {
    for (const AnalyticCase& c : analytic_cases()) {
        const PreparedMesh mesh = prepare_mesh(c.mesh);
        const WindingSign sign(mesh);
        int tested = 0;
        for (const Vec3d& p : random_points(2000, {-1.5, -1.5, -1.5}, {1.5, 1.5, 1.5}, 11)) {
            const double d = c.sdf(p);
            if (std::abs(d) < c.margin) continue;
            const double truth = d < 0 ? 1.0 : 0.0;
            ASSERT_NEAR(exact_winding(mesh, p), truth, 1e-10) << c.name << " at " << p.x << " " << p.y << " " << p.z;
            const WindingEstimate<double> fast = sign.estimate(p);
            ASSERT_LE(std::abs(fast.value - truth), fast.error_bound + 1e-12) << c.name;
            ASSERT_EQ(sign.inside(p), d < 0) << c.name;
            ++tested;
        }
        EXPECT_GT(tested, 1500) << c.name;
    }
}

// ---- Overlapping closed parts: two spheres and a box through both ---------------------

struct Parts {
    TriangleMesh mesh = test::concatenated({make_icosphere(3, 0.6, {-0.5, 0, 0}), make_icosphere(3, 0.6, {0.5, 0, 0}),
                                      make_box({1.3, 0.2, 0.2}, {0, 0, 0})});
    /// Number of parts containing p (analytic spheres; the mesh spheres lie within 0.01 of them).
    static int depth(const Vec3d& p) {
        return int(test::sphere_sdf(p - Vec3d{-0.5, 0, 0}, 0.6) < 0) + int(test::sphere_sdf(p - Vec3d{0.5, 0, 0}, 0.6) < 0) +
               int(test::box_sdf(p, {1.3, 0.2, 0.2}) < 0);
    }
    static double surface_distance(const Vec3d& p) {
        return std::min({std::abs(test::sphere_sdf(p - Vec3d{-0.5, 0, 0}, 0.6)), std::abs(test::sphere_sdf(p - Vec3d{0.5, 0, 0}, 0.6)),
                         std::abs(test::box_sdf(p, {1.3, 0.2, 0.2}))});
    }
};

TEST(WindingNumber, OverlappingPartsCountTheirDepthAndSignTheUnion) {
    const Parts parts;
    const PreparedMesh mesh = prepare_mesh(parts.mesh);
    EXPECT_EQ(mesh.report().components, 3);
    EXPECT_EQ(mesh.report().overlapping_shells, 3);
    EXPECT_EQ(choose_sign_mode(mesh.report()).mode, SignMode::Winding);

    const WindingSign sign(mesh);
    SamplerOptions o;
    o.precision = Precision::Double;
    o.progress = false;
    o.sign = SignMode::Pseudonormal;  // auto would pick the winding sign here
    const std::vector<Vec3d> points = random_points(3000, {-1.5, -0.8, -0.8}, {1.5, 0.8, 0.8}, 5);
    const std::vector<PointSample> pseudonormal = make_cpu_brute_force_sampler(o)->bind(share(mesh))->query(points);
    int tested = 0, pseudonormal_wrong = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        const Vec3d& p = points[i];
        if (Parts::surface_distance(p) < 0.02) continue;
        ++tested;
        ASSERT_NEAR(exact_winding(mesh, p), double(Parts::depth(p)), 1e-9);
        ASSERT_EQ(sign.inside(p), Parts::depth(p) > 0) << p.x << " " << p.y << " " << p.z;
        pseudonormal_wrong += int((pseudonormal[i].distance < 0) != (Parts::depth(p) > 0));
    }
    EXPECT_GT(tested, 2000);
    // The failure the winding sign exists for: inside one part near another's surface the
    // pseudonormal of that surface says "outside".
    EXPECT_GT(pseudonormal_wrong, 0);
}

// ---- Fast vs exact: the error bound holds everywhere ----------------------------------

/// A soccer ball with its seams (3,500 triangles) and an open bowl: half an icosphere.
std::vector<PreparedMesh> bound_meshes() {
    TriangleMesh bowl = make_icosphere(3, 1.0);
    std::vector<Int3> kept;
    for (const Int3& t : bowl.triangles)
        if (bowl.vertices[size_t(t.x)].z + bowl.vertices[size_t(t.y)].z + bowl.vertices[size_t(t.z)].z < 0.6) kept.push_back(t);
    bowl.triangles = kept;
    std::vector<PreparedMesh> out;
    out.push_back(prepare_mesh(make_soccer_ball(2)));
    out.push_back(prepare_mesh(bowl));
    return out;
}

TEST(FastWindingNumber, ErrorStaysWithinTheStatedBound) {
    for (const PreparedMesh& mesh : bound_meshes()) {
        const WindingSign sign(mesh);
        // Near the surface (where the far field is used least) and far away (most).
        std::vector<Vec3d> points = random_points(600, {-1.3, -1.3, -1.3}, {1.3, 1.3, 1.3}, 3);
        for (const Vec3d& p : random_points(200, {-6, -6, -6}, {6, 6, 6}, 4)) points.push_back(p);
        for (const int order : {1, 2})
            for (const double beta : {1.5, 2.0, 3.0}) {
                double worst_ratio = 0;
                int decided = 0;
                for (const Vec3d& p : points) {
                    const double exact = exact_winding(mesh, p);
                    const WindingEstimate<double> fast = sign.estimate(p, {beta, order});
                    const double error = std::abs(fast.value - exact);
                    ASSERT_LE(error, fast.error_bound + 1e-12) << mesh.name() << " order " << order << " beta " << beta;
                    if (fast.error_bound > 0) worst_ratio = std::max(worst_ratio, error / fast.error_bound);
                    if (std::abs(exact - 0.5) > fast.error_bound) {
                        ++decided;
                        ASSERT_EQ(fast.value > 0.5, exact > 0.5) << mesh.name();
                    }
                }
                // The bound is rigorous but pessimistic (worst cases summed over the accepted
                // children): at beta 3 and order 2 it decides most of these points.
                if (order == 2 && beta == 3.0) {
                    EXPECT_GT(decided, int(points.size()) / 2) << mesh.name();
                }
                EXPECT_LE(worst_ratio, 1.0);
            }
        // beta = infinity opens everything: the exact sum (in BVH order), bound 0.
        for (size_t i = 0; i < 50; ++i) {
            const WindingEstimate<double> all = sign.estimate(points[i], {kInf, 2});
            EXPECT_EQ(all.error_bound, 0.0);
            EXPECT_NEAR(all.value, exact_winding(mesh, points[i]), 1e-12);
        }
    }
}

// The moments are computed node by node on every thread; each node's sums are its own, so
// the moments are the same bytes on 1 thread as on 3.
TEST(FastWindingNumber, MomentsAreTheSameBytesAtEveryThreadCount) {
    std::vector<PreparedMesh> meshes = bound_meshes();
    meshes.push_back(prepare_mesh(make_icosphere(5, 1.0)));
    for (const PreparedMesh& mesh : meshes) {
        const WindingBvh one = build_winding_bvh(mesh, mesh.bvh(), 1), three = build_winding_bvh(mesh, mesh.bvh(), 3);
        ASSERT_EQ(one.moments.size(), three.moments.size());
        ASSERT_EQ(std::memcmp(one.moments.data(), three.moments.data(), one.moments.size() * sizeof(one.moments[0])), 0)
            << mesh.name();
        ASSERT_EQ(std::memcmp(one.moments_float.data(), three.moments_float.data(),
                              one.moments_float.size() * sizeof(one.moments_float[0])),
                  0)
            << mesh.name();
    }
}

// ---- The certified sign ---------------------------------------------------------------

TEST(WindingSign, ClosedMeshesAgreeWithThePseudonormalSignOffExactTies) {
    for (const TriangleMesh& shape : {make_soccer_ball(2), make_pawn(), make_torus(1.0, 0.35, 24, 12)}) {
        const PreparedMesh mesh = prepare_mesh(shape);
        ASSERT_EQ(choose_sign_mode(mesh.report()).mode, SignMode::Pseudonormal) << choose_sign_mode(mesh.report()).reason;
        const WindingSign sign(mesh);
        const Bounds3 b = mesh.bounds();
        const Vec3d pad = b.extent() * 0.2;
        const std::vector<Vec3d> points = random_points(4000, b.min - pad, b.max + pad, 9);
        SamplerOptions o;
        o.precision = Precision::Double;
        o.progress = false;
        o.sign = SignMode::Pseudonormal;
        const std::vector<PointSample> s = make_cpu_brute_force_sampler(o)->bind(share(mesh))->query(points);
        for (size_t i = 0; i < points.size(); ++i) {
            if (std::abs(s[i].distance) < 1e-12) continue;
            ASSERT_EQ(sign.inside(points[i]), s[i].distance < 0) << shape.name << " point " << i;
        }
    }
}

TEST(WindingSign, OpenAndOverlappingMeshesAgreeWithTheExactWindingNumber) {
    std::vector<PreparedMesh> meshes = bound_meshes();
    meshes.push_back(prepare_mesh(Parts().mesh));
    for (const PreparedMesh& mesh : meshes) {
        const WindingSign fast(mesh);  // beta 2, order 2, uncertified
        WindingSignOptions o;
        o.accuracy = {2.0, 1};  // order 1 at beta 2: many points to refine, exercising the chain
        o.certify = true;
        const WindingSign certified(mesh, o);
        int clear = 0, refined = 0;
        for (const Vec3d& p : random_points(1500, mesh.bounds().min - Vec3d(0.3), mesh.bounds().max + Vec3d(0.3), 21)) {
            const double w = exact_winding(mesh, p);
            if (std::abs(w - 0.5) > 0.2) {
                ++clear;
                ASSERT_EQ(fast.inside(p), w > 0.5) << mesh.name() << " w = " << w;
            }
            if (std::abs(w - 0.5) < 1e-9) continue;  // numerically on the w = 1/2 surface
            const WindingSide side = certified.side(p);
            refined += side.stage != WindingStage::Fast;
            ASSERT_EQ(side.inside, w > 0.5) << mesh.name() << " w = " << w;
        }
        EXPECT_GT(clear, 1000) << mesh.name();
        EXPECT_GT(refined, 0) << mesh.name();
    }
}

TEST(WindingSign, WithSignKeepsDistanceAndGradientMagnitude) {
    SignedDistanceSample<double> s;
    s.distance = 0.25;
    s.gradient = {0, 0.6, 0.8};
    const SignedDistanceSample<double> in = with_sign(s, true);
    EXPECT_EQ(in.distance, -0.25);
    EXPECT_EQ(in.gradient, (Vec3d{0, -0.6, -0.8}));
    EXPECT_EQ(with_sign(in, true).distance, -0.25);
    EXPECT_EQ(with_sign(s, false).distance, 0.25);
}

TEST(SignMode, AutoExplainsItsChoice) {
    MeshReport r;
    r.components = 1;
    r.intersections_checked = true;
    EXPECT_EQ(choose_sign_mode(r).mode, SignMode::Pseudonormal);
    EXPECT_EQ(choose_sign_mode(r, SignMode::Winding).mode, SignMode::Winding);
    MeshReport open = r;
    open.boundary_edges = 12;
    EXPECT_EQ(choose_sign_mode(open).mode, SignMode::Winding);
    EXPECT_NE(choose_sign_mode(open).reason.find("open (12 boundary edges)"), std::string::npos);
    MeshReport crossing = r;
    crossing.self_intersecting_pairs = 25;
    EXPECT_NE(choose_sign_mode(crossing).reason.find("intersects itself (25 triangle pairs)"), std::string::npos);
    MeshReport shells = r;
    shells.components = 3;
    EXPECT_NE(choose_sign_mode(shells).reason.find("3 shells"), std::string::npos);
    MeshReport unchecked = r;
    unchecked.intersections_checked = false;
    EXPECT_EQ(choose_sign_mode(unchecked).mode, SignMode::Winding);
    EXPECT_EQ(sign_mode_from_name("winding", "k"), SignMode::Winding);
    EXPECT_THROW(sign_mode_from_name("parity", "config.json: key 'sign'"), std::invalid_argument);
}

}  // namespace
}  // namespace sdf
