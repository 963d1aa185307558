// The procedural shapes: closed, outward, genus as designed, exact triangle counts, volumes
// against the analytic solids, deterministic. Topology (edges, Euler characteristic, solid
// angles) is recounted here from the raw triangles, not taken from prepare_mesh().
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"

namespace sdf {
namespace {

constexpr double kPi = 3.14159265358979323846;

int count_edges(const std::vector<Int3>& triangles) {
    std::set<std::pair<int, int>> edges;
    for (const Int3& t : triangles)
        for (int e = 0; e < 3; ++e) edges.insert(std::minmax(t[e], t[(e + 1) % 3]));
    return int(edges.size());
}

/// What every generator promises: a clean, closed, outward 2-manifold in one piece.
void expect_clean_closed_surface(const TriangleMesh& mesh, int euler_characteristic) {
    SCOPED_TRACE(mesh.source);
    const PreparedMesh m = prepare_mesh(mesh);
    const MeshReport& r = m.report();
    EXPECT_TRUE(r.closed()) << r.boundary_edges << " boundary, " << r.nonmanifold_edges << " non-manifold";
    EXPECT_TRUE(r.consistently_oriented()) << r.inconsistent_edges << " inconsistent edges";
    EXPECT_FALSE(r.flipped);
    EXPECT_GT(r.signed_volume, 0.0);
    EXPECT_EQ(r.components, 1);
    EXPECT_EQ(r.degenerate_triangles, 0);
    EXPECT_EQ(r.welded_vertices, 0) << "generators share vertices by index, never by position";
    EXPECT_EQ(r.unreferenced_vertices, 0);
    const int v = int(mesh.vertices.size()), f = int(mesh.triangles.size());
    EXPECT_EQ(v - count_edges(mesh.triangles) + f, euler_characteristic);
    EXPECT_TRUE(m.warnings().empty());
}

double signed_volume(const TriangleMesh& mesh) {
    double volume = 0.0;
    for (const Int3& t : mesh.triangles)
        volume += dot(mesh.vertices[size_t(t.x)],
                      cross(mesh.vertices[size_t(t.y)], mesh.vertices[size_t(t.z)])) / 6.0;
    return volume;
}

/// Solid angle of triangle abc seen from the origin (Van Oosterom & Strackee 1983); positive
/// when the triangle turns its front (counter-clockwise side) to the origin's outside.
double solid_angle(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const double la = length(a), lb = length(b), lc = length(c);
    const double denominator = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    return 2.0 * std::atan2(dot(a, cross(b, c)), denominator);
}

/// Every triangle faces away from the origin and together they wrap it exactly once: the
/// surface is star-shaped about the origin, so no two triangles can intersect.
void expect_star_shaped_about_origin(const TriangleMesh& mesh) {
    double total = 0.0;
    int facing_origin = 0;
    for (const Int3& t : mesh.triangles) {
        const Vec3d& a = mesh.vertices[size_t(t.x)];
        const Vec3d& b = mesh.vertices[size_t(t.y)];
        const Vec3d& c = mesh.vertices[size_t(t.z)];
        if (dot(cross(b - a, c - a), a) <= 0.0) ++facing_origin;
        total += solid_angle(a, b, c);
    }
    EXPECT_EQ(facing_origin, 0);
    EXPECT_NEAR(total, 4.0 * kPi, 1e-9);
}

double max_radius(const TriangleMesh& mesh) {
    double r = 0.0;
    for (const Vec3d& v : mesh.vertices) r = std::max(r, length(v));
    return r;
}

double min_radius(const TriangleMesh& mesh) {
    double r = 1e300;
    for (const Vec3d& v : mesh.vertices) r = std::min(r, length(v));
    return r;
}

TEST(Icosphere, ClosedGenusZeroWithExactCounts) {
    for (int k = 0; k <= 4; ++k) {
        const TriangleMesh mesh = make_icosphere(k);
        EXPECT_EQ(mesh.triangles.size(), size_t(20) << (2 * k));
        EXPECT_EQ(mesh.vertices.size(), (size_t(10) << (2 * k)) + 2);
        expect_clean_closed_surface(mesh, 2);
        expect_star_shaped_about_origin(mesh);
    }
}

// Vertices lie on the sphere, so the convex polyhedron lies between the sphere and the ball
// of its smallest face distance (the chord error): the volume is bracketed by the two.
TEST(Icosphere, VolumeApproachesTheBallWithinTheChordError) {
    const double radius = 1.5;
    const double ball = 4.0 / 3.0 * kPi * radius * radius * radius;
    double previous_error = 1e300;
    for (int k = 0; k <= 4; ++k) {
        const TriangleMesh mesh = make_icosphere(k, radius, {0.25, -0.5, 1.0});
        const Vec3d center{0.25, -0.5, 1.0};
        double inradius = radius;
        for (const Int3& t : mesh.triangles) {
            const Vec3d a = mesh.vertices[size_t(t.x)] - center, b = mesh.vertices[size_t(t.y)] - center,
                        c = mesh.vertices[size_t(t.z)] - center;
            inradius = std::min(inradius, dot(normalize_or_zero(cross(b - a, c - a)), a));
        }
        const double volume = prepare_mesh(mesh).report().signed_volume;
        EXPECT_LE(volume, ball * (1 + 1e-12)) << "k=" << k;
        EXPECT_GE(volume, ball * std::pow(inradius / radius, 3) * (1 - 1e-12)) << "k=" << k;
        EXPECT_LT(ball - volume, previous_error) << "k=" << k;
        previous_error = ball - volume;
    }
    EXPECT_LT(previous_error / ball, 3e-3);  // 5,120 triangles: within 0.3 %
}

TEST(Box, TwelveTrianglesAndExactVolume) {
    // Dyadic sizes and centre: every triple product in the volume sum is exact in double; only
    // the division by 6 of each term rounds.
    const TriangleMesh mesh = make_box({1.0, 2.0, 0.5}, {0.25, -1.0, 3.0});
    EXPECT_EQ(mesh.triangles.size(), 12u);
    EXPECT_EQ(mesh.vertices.size(), 8u);
    expect_clean_closed_surface(mesh, 2);
    EXPECT_NEAR(prepare_mesh(mesh).report().signed_volume, 8.0 * 1.0 * 2.0 * 0.5, 1e-14);
    const Bounds3 b = triangle_bounds(mesh.vertices, mesh.triangles);
    EXPECT_EQ(b.min, (Vec3d{-0.75, -3.0, 2.5}));
    EXPECT_EQ(b.max, (Vec3d{1.25, 1.0, 3.5}));
}

TEST(Torus, ClosedGenusOneWithExactCounts) {
    for (const auto& [major, minor] : {std::pair{64, 32}, std::pair{12, 5}, std::pair{3, 3}}) {
        const TriangleMesh mesh = make_torus(1.0, 0.35, major, minor);
        EXPECT_EQ(mesh.triangles.size(), size_t(2 * major * minor));
        EXPECT_EQ(mesh.vertices.size(), size_t(major * minor));
        expect_clean_closed_surface(mesh, 0);
    }
}

// Relative error of an inscribed polygon's area is below 2 (1 - cos(pi/n)), twice its
// relative chord sagitta; the tube's section and its sweep each contribute one such term.
TEST(Torus, VolumeApproachesTheSolidWithinTheChordError) {
    const double R = 1.0, r = 0.35;
    const double solid = 2.0 * kPi * kPi * R * r * r;
    double previous_error = 1e300;
    for (int n : {8, 16, 32, 64}) {
        const TriangleMesh mesh = make_torus(R, r, 2 * n, n);
        const double error = std::abs(signed_volume(mesh) - solid) / solid;
        const double bound = 2.0 * (1.0 - std::cos(kPi / n)) + 2.0 * (1.0 - std::cos(kPi / (2 * n)));
        EXPECT_LT(error, bound) << "n=" << n;
        EXPECT_LT(error, previous_error) << "n=" << n;
        previous_error = error;
    }
    EXPECT_LT(previous_error, 0.01);
}

TEST(Pawn, ThreeHundredFourTrianglesAtTheDefaultSlices) {
    const TriangleMesh mesh = make_pawn();
    EXPECT_EQ(mesh.name, "pawn");
    EXPECT_EQ(mesh.triangles.size(), 304u);  // the thesis's pawn
    EXPECT_EQ(mesh.vertices.size(), 154u);   // closed genus 0: V = T/2 + 2
    expect_clean_closed_surface(mesh, 2);
}

TEST(Pawn, ClosedForAnyNumberOfSlices) {
    for (int segments : {3, 4, 5, 7, 8, 16, 33, 64}) {
        const TriangleMesh mesh = make_pawn(segments);
        // 9 full rings, a half ring under the top pole, 2 poles.
        const size_t vertices = 2 + 9 * size_t(segments) + size_t(std::max(3, segments / 2));
        EXPECT_EQ(mesh.vertices.size(), vertices) << segments;
        EXPECT_EQ(mesh.triangles.size(), 2 * vertices - 4) << segments;
        expect_clean_closed_surface(mesh, 2);
    }
    EXPECT_THROW(make_pawn(2), std::invalid_argument);
}

TEST(Pawn, OneUnitTallStandingOnTheXZPlaneAroundTheYAxis) {
    const TriangleMesh mesh = make_pawn();
    const Bounds3 b = triangle_bounds(mesh.vertices, mesh.triangles);
    EXPECT_EQ(b.min.y, 0.0);
    EXPECT_NEAR(b.max.y, 1.0, 1e-12);
    EXPECT_NEAR(b.max.x, -b.min.x, 1e-12);  // symmetric about the axis
    EXPECT_NEAR(b.max.z, -b.min.z, 1e-12);
    EXPECT_GT(b.extent().x, 0.4);           // a base wide enough to stand on
    EXPECT_LT(b.extent().x, 0.8);
    // Volume: between a thin rod and the cylinder around it.
    const double volume = prepare_mesh(mesh).report().signed_volume;
    EXPECT_GT(volume, 0.02);
    EXPECT_LT(volume, kPi * 0.25 * b.extent().x * b.extent().x);
}

TEST(SoccerBall, DesignedCountsNearTheThesisBall) {
    const TriangleMesh mesh = make_soccer_ball();
    EXPECT_EQ(mesh.name, "soccer_ball");
    // Thesis: 3,516 triangles and 1,760 vertices; this construction, 180 (n^2 + 4n), n = detail + 1.
    EXPECT_EQ(mesh.triangles.size(), 3780u);
    EXPECT_EQ(mesh.vertices.size(), 1892u);
    EXPECT_NEAR(double(mesh.triangles.size()), 3516.0, 0.1 * 3516.0);
    for (int detail = 0; detail <= 3; ++detail) {
        const size_t n = size_t(detail) + 1;
        EXPECT_EQ(make_soccer_ball(detail).triangles.size(), 180 * (n * n + 4 * n)) << detail;
    }
}

TEST(SoccerBall, ClosedStarShapedGenusZero) {
    for (int detail = 0; detail <= 3; ++detail) {
        const TriangleMesh mesh = make_soccer_ball(detail);
        expect_clean_closed_surface(mesh, 2);
        expect_star_shaped_about_origin(mesh);
    }
    const TriangleMesh wide = make_soccer_ball(2, 0.05, 0.12);
    expect_clean_closed_surface(wide, 2);
    expect_star_shaped_about_origin(wide);
}

TEST(SoccerBall, UnitRadiusWithSeamsEngravedToTheirDepth) {
    for (double depth : {0.02, 0.05}) {
        const TriangleMesh mesh = make_soccer_ball(2, depth, 0.03);
        EXPECT_NEAR(max_radius(mesh), 1.0, 1e-12);
        EXPECT_NEAR(min_radius(mesh), 1.0 - depth, 1e-12);
        int on_sphere = 0, deep = 0;
        for (const Vec3d& v : mesh.vertices) {
            on_sphere += std::abs(length(v) - 1.0) < 1e-12;
            deep += length(v) < 1.0 - depth / 2;
        }
        // The panels up to the groove's edge stay on the sphere (centres and 3 grid rings:
        // 32 + 6 * 180); the seam outlines (60 corners, 2 vertices inside each of 90 seams)
        // and the flank rings (3 * 180, at 3/4 depth) sink below half depth.
        EXPECT_EQ(on_sphere, 32 + 6 * 180);
        EXPECT_EQ(deep, 60 + 2 * 90 + 3 * 180);
    }
    // Without depth it is a tessellated sphere, inside the unit ball.
    const double volume = prepare_mesh(make_soccer_ball(2, 0.0, 0.03)).report().signed_volume;
    EXPECT_LT(volume, 4.0 / 3.0 * kPi);
    EXPECT_GT(volume, 4.0 / 3.0 * kPi * 0.97);
}

TEST(SoccerBall, RejectsArgumentsOutsideTheirRange) {
    EXPECT_THROW(make_soccer_ball(-1), std::invalid_argument);
    EXPECT_THROW(make_soccer_ball(2, -0.01), std::invalid_argument);
    EXPECT_THROW(make_soccer_ball(2, 0.02, 0.0), std::invalid_argument);
    EXPECT_THROW(make_soccer_ball(2, 0.02, 0.5), std::invalid_argument);
}

TEST(ProceduralShapes, DeterministicAndHashedByGeometry) {
    const auto same = [](const TriangleMesh& a, const TriangleMesh& b) {
        EXPECT_EQ(a.content_sha256, b.content_sha256) << a.name;
        EXPECT_EQ(a.content_sha256, geometry_sha256(a)) << a.name;
        EXPECT_EQ(a.content_sha256.size(), 64u) << a.name;
    };
    same(make_icosphere(3), make_icosphere(3));
    same(make_box(), make_box());
    same(make_torus(), make_torus());
    same(make_pawn(), make_pawn());
    same(make_soccer_ball(), make_soccer_ball());
    EXPECT_NE(make_pawn(16).content_sha256, make_pawn(17).content_sha256);
    EXPECT_NE(make_soccer_ball(2, 0.02).content_sha256, make_soccer_ball(2, 0.03).content_sha256);
}

}  // namespace
}  // namespace sdf
