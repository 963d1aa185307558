// Eberly's point-triangle distance and the branch-free packed form, against an independent
// double-precision reference written here from first principles (plane projection, else
// the nearest of the three edge segments).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "kernels/distance/closest_point_on_triangle.h"
#include "kernels/distance/packed_triangle.h"

namespace sdf {
namespace {

Vec3d nearest_on_segment(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
    const Vec3d ab = b - a;
    const double len2 = dot(ab, ab);
    double u = len2 > 0 ? dot(p - a, ab) / len2 : 0.0;
    u = std::clamp(u, 0.0, 1.0);
    return a + ab * u;
}

/// Independent truth: the projection if it falls inside, else the best edge point.
double reference_distance_squared(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const Vec3d n = cross(b - a, c - a);
    const double n2 = dot(n, n);
    if (n2 > 0) {
        const Vec3d q = p - n * (dot(p - a, n) / n2);
        const bool inside = dot(cross(b - a, q - a), n) >= 0 && dot(cross(c - b, q - b), n) >= 0 &&
                            dot(cross(a - c, q - c), n) >= 0;
        if (inside) return length_squared(p - q);
    }
    return std::min({length_squared(p - nearest_on_segment(p, a, b)),
                     length_squared(p - nearest_on_segment(p, b, c)),
                     length_squared(p - nearest_on_segment(p, c, a))});
}

struct Case {
    Vec3d p, a, b, c;
};

std::vector<Case> random_cases(int n, unsigned seed, bool slivers) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Case> cases;
    for (int i = 0; i < n; ++i) {
        Case k;
        k.a = {u(rng), u(rng), u(rng)};
        k.b = {u(rng), u(rng), u(rng)};
        k.c = {u(rng), u(rng), u(rng)};
        if (slivers) k.c = k.a + (k.b - k.a) * (0.5 + 0.5 * u(rng)) + Vec3d(u(rng), u(rng), u(rng)) * 1e-4;
        k.p = Vec3d{u(rng), u(rng), u(rng)} * 2.0;
        cases.push_back(k);
    }
    return cases;
}

TEST(ClosestPointOnTriangle, MatchesIndependentReferenceInDouble) {
    for (bool slivers : {false, true}) {
        for (const Case& k : random_cases(20000, 7 + slivers, slivers)) {
            const auto r = closest_point_on_triangle(k.p, k.a, k.b, k.c);
            const double ref = reference_distance_squared(k.p, k.a, k.b, k.c);
            ASSERT_NEAR(r.distance_squared, ref, 1e-12 * std::max(1.0, ref)) << "sliver=" << slivers;
            EXPECT_GE(r.s, 0.0);
            EXPECT_GE(r.t, 0.0);
            EXPECT_LE(r.s + r.t, 1.0 + 1e-12);
        }
    }
}

TEST(ClosestPointOnTriangle, FeatureMatchesClosestPoint) {
    for (const Case& k : random_cases(20000, 11, false)) {
        const auto r = closest_point_on_triangle(k.p, k.a, k.b, k.c);
        switch (r.feature) {
            case TriangleFeature::Vertex0: EXPECT_EQ(r.point, k.a); break;
            case TriangleFeature::Vertex1: EXPECT_EQ(r.point, k.b); break;
            case TriangleFeature::Vertex2: EXPECT_EQ(r.point, k.c); break;
            case TriangleFeature::Edge01: EXPECT_EQ(r.t, 0.0); EXPECT_GT(r.s, 0.0); EXPECT_LT(r.s, 1.0); break;
            case TriangleFeature::Edge20: EXPECT_EQ(r.s, 0.0); EXPECT_GT(r.t, 0.0); EXPECT_LT(r.t, 1.0); break;
            case TriangleFeature::Edge12: EXPECT_NEAR(r.s + r.t, 1.0, 1e-15); EXPECT_GT(r.s, 0.0); break;
            case TriangleFeature::Face: EXPECT_GT(r.s, 0.0); EXPECT_GT(r.t, 0.0); EXPECT_LT(r.s + r.t, 1.0); break;
        }
    }
}

TEST(ClosestPointOnTriangle, AllSevenRegionsAreReached) {
    // Unit right triangle in the z = 0 plane; one probe per region of thesis Figure 3-1.
    const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
    struct Probe { Vec3d p; TriangleFeature f; double d2; };
    const Probe probes[] = {
        {{0.25, 0.25, 1}, TriangleFeature::Face, 1.0},          // region 0
        {{1, 1, 0}, TriangleFeature::Edge12, 0.5},              // region 1
        {{-1, 2, 0}, TriangleFeature::Vertex2, 2.0},            // region 2
        {{-1, 0.5, 0}, TriangleFeature::Edge20, 1.0},           // region 3
        {{-1, -1, 0}, TriangleFeature::Vertex0, 2.0},           // region 4
        {{0.5, -1, 0}, TriangleFeature::Edge01, 1.0},           // region 5
        {{2, -1, 0}, TriangleFeature::Vertex1, 2.0},            // region 6
    };
    for (const Probe& pr : probes) {
        const auto r = closest_point_on_triangle(pr.p, a, b, c);
        EXPECT_EQ(r.feature, pr.f) << feature_name(pr.f);
        EXPECT_DOUBLE_EQ(r.distance_squared, pr.d2) << feature_name(pr.f);
    }
}

TEST(ClosestPointOnTriangle, DegenerateTriangles) {
    const Vec3d p{0.3, 0.7, -0.2};
    // Collinear and point-like triangles fall back to the nearest edge point.
    const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{2, 0, 0};
    EXPECT_NEAR(closest_point_on_triangle(p, a, b, c).distance_squared, reference_distance_squared(p, a, b, c),
                1e-15);
    const auto r = closest_point_on_triangle(p, a, a, a);
    EXPECT_NEAR(r.distance_squared, length_squared(p), 1e-15);
    EXPECT_TRUE(is_vertex(r.feature));
}

/// Radius of the inscribed circle: 2 area / perimeter.
double inradius(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    return length(cross(b - a, c - a)) / (length(b - a) + length(c - b) + length(a - c));
}

TEST(PackedTriangle, MatchesReferenceInDoubleAndFloat) {
    for (const Case& k : random_cases(20000, 3, false)) {
        const double ref = reference_distance_squared(k.p, k.a, k.b, k.c);
        const double qd = squared_distance(pack_triangle<double>(k.a, k.b, k.c), k.p);
        ASSERT_NEAR(qd, ref, 1e-12 * std::max(1.0, ref));
        const PackedTriangle<float> pf = pack_triangle<float>(k.a, k.b, k.c);
        const float qf = squared_distance(pf, Vec3f(k.p));
        // Float: the edge terms expand |B - P|^2 + ..., so the rounding error scales with
        // the squared lengths involved, not with the result; a float sliver (sin^2 of an angle
        // below kFloatSliverSin2) is searched by its edges and over-estimates by at most its
        // sliver_excess (0 for every other triangle).
        const double scale = length_squared(k.a - k.p) + length_squared(k.b - k.a) + length_squared(k.c - k.a);
        ASSERT_GE(qf, ref - 4e-7 * scale);
        ASSERT_LE(qf, ref + double(sliver_excess(pf)) + 4e-7 * scale);
    }
}

TEST(PackedTriangle, SliversAreSearchedByTheirEdges) {
    // Slivers (here 1e-4 wide) never count as "inside": Q is the nearest edge's, which
    // over-estimates the true value by at most the squared inradius.
    for (const Case& k : random_cases(20000, 4, true)) {
        const double ref = reference_distance_squared(k.p, k.a, k.b, k.c);
        const double r = inradius(k.a, k.b, k.c);
        for (double q : {squared_distance(pack_triangle<double>(k.a, k.b, k.c), k.p),
                         double(squared_distance(pack_triangle<float>(k.a, k.b, k.c), Vec3f(k.p)))}) {
            const double scale = length_squared(k.a - k.p) + length_squared(k.b - k.a) + length_squared(k.c - k.a);
            ASSERT_GE(q, ref - 4e-7 * scale);
            ASSERT_LE(q, ref + r * r + 4e-7 * scale);
        }
    }
}

TEST(PackedTriangle, ZeroAreaTriangleUsesItsEdges) {
    const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{2, 0, 0}, p{0.5, 1, 0};
    EXPECT_NEAR(squared_distance(pack_triangle<double>(a, b, c), p), 1.0, 1e-15);
    EXPECT_NEAR(squared_distance(pack_triangle<double>(a, a, a), p), 1.25, 1e-15);
}

}  // namespace
}  // namespace sdf
