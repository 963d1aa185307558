// Self-intersection and overlapping-shell detection: the triangle-pair predicate on
// constructed pairs (crossing, touching, sharing an edge or a corner, folded), the BVH
// search on closed shapes (none), overlapping and nested shells, and dragon-legacy.obj
// (25 intersecting pairs, as counted for the issue); edges on one line (exact predicates);
// no reported pair with disjoint boxes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <sstream>

#include "core/mesh/exact_predicates.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/self_intersections.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/mesh/triangle_intersection.h"

namespace sdf {
namespace {

bool intersect(const Vec3d (&a)[3], Int3 ia, const Vec3d (&b)[3], Int3 ib) {
    const bool ab = triangles_intersect(a, ia, b, ib), ba = triangles_intersect(b, ib, a, ia);
    EXPECT_EQ(ab, ba) << "the predicate must be symmetric";
    return ab;
}

const Vec3d kFlat[3] = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};  // in z = 0
const Int3 kFlatIds{0, 1, 2};

TEST(TrianglesIntersect, SeparateTrianglesCrossingOrNot) {
    const Vec3d piercing[3] = {{0.5, 0.5, -1}, {0.5, 0.5, 1}, {0.6, 0.4, 1}};
    const Vec3d above[3] = {{0.5, 0.5, 0.1}, {0.5, 0.6, 1}, {0.6, 0.4, 1}};
    const Vec3d touching_corner[3] = {{0.5, 0.5, 0}, {0.5, 0.6, 1}, {0.6, 0.4, 1}};  // a corner on the face
    const Vec3d coplanar_overlap[3] = {{1, 1, 0}, {3, 1, 0}, {1, 3, 0}};
    const Vec3d coplanar_apart[3] = {{3, 3, 0}, {4, 3, 0}, {3, 4, 0}};
    const Int3 other{3, 4, 5};
    EXPECT_TRUE(intersect(kFlat, kFlatIds, piercing, other));
    EXPECT_FALSE(intersect(kFlat, kFlatIds, above, other));
    EXPECT_TRUE(intersect(kFlat, kFlatIds, touching_corner, other));
    EXPECT_TRUE(intersect(kFlat, kFlatIds, coplanar_overlap, other));
    EXPECT_FALSE(intersect(kFlat, kFlatIds, coplanar_apart, other));
    // T-junctions: a corner on the other's edge (no shared vertex id) counts, as in CGAL:
    // the closed triangles have a common point.
    const Vec3d t_coplanar[3] = {{1, 0, 0}, {1, -1, 0}, {2, -1, 0}};
    const Vec3d t_across[3] = {{1, 0, 0}, {1, -1, 1}, {1, -1, -1}};
    const Vec3d t_near[3] = {{1, -1e-12, 0}, {1, -1, 0}, {2, -1, 0}};
    EXPECT_TRUE(intersect(kFlat, kFlatIds, t_coplanar, other));
    EXPECT_TRUE(intersect(kFlat, kFlatIds, t_across, other));
    EXPECT_FALSE(intersect(kFlat, kFlatIds, t_near, other));
}

TEST(TrianglesIntersect, SharedEdgeOnlyWhenFoldedOntoEachOther) {
    const Vec3d hinge[3] = {{2, 0, 0}, {0, 0, 0}, {1, -1, 0.5}};  // shares edge 0-1, bends away
    const Vec3d flat_neighbour[3] = {{2, 0, 0}, {0, 0, 0}, {1, -1, 0}};
    const Vec3d folded[3] = {{2, 0, 0}, {0, 0, 0}, {0.5, 0.5, 0}};  // third corner on the same side
    const Int3 ids{1, 0, 7};
    EXPECT_FALSE(intersect(kFlat, kFlatIds, hinge, ids));
    EXPECT_FALSE(intersect(kFlat, kFlatIds, flat_neighbour, ids));
    EXPECT_TRUE(intersect(kFlat, kFlatIds, folded, ids));
    EXPECT_TRUE(intersect(kFlat, kFlatIds, kFlat, kFlatIds));  // the same triangle twice
}

TEST(TrianglesIntersect, SharedCornerOnlyWhenTheOppositeEdgePierces) {
    const Vec3d fan[3] = {{0, 0, 0}, {-1, 0, 1}, {-1, -1, 1}};            // shares corner 0, elsewhere
    const Vec3d through[3] = {{0, 0, 0}, {1, 1, -1}, {1, 0.5, 1}};         // its far edge crosses the face
    const Vec3d coplanar_inside[3] = {{0, 0, 0}, {0.5, 0.2, 0}, {0.2, 0.5, 0}};
    const Int3 ids{0, 8, 9};
    EXPECT_FALSE(intersect(kFlat, kFlatIds, fan, ids));
    EXPECT_TRUE(intersect(kFlat, kFlatIds, through, ids));
    EXPECT_TRUE(intersect(kFlat, kFlatIds, coplanar_inside, ids));
}

/// Triangles with an edge on one line, exactly: points a + k d with a, d and the off-line
/// directions on a 2^-36 grid, so that every point is a double (collinear in exact
/// arithmetic) while the products in the orientation determinants round. Rounded
/// determinants call such pairs crossing (the CAD model of issue 22: collinear edges of
/// fans); exact ones see two segments of a line that are apart, touch or overlap.
struct CollinearEdges {
    Vec3d a, d, e, f;
    Vec3d at(double k, const Vec3d& off = {}) const { return a + d * k + off; }
    /// (a, a + 2d, a + d + e) and the triangle whose edge spans [from, from + 2] on the line,
    /// with its third corner off the line along f.
    bool meet(double from) const {
        const Vec3d t1[3] = {at(0), at(2), at(1, e)}, t2[3] = {at(from), at(from + 2), at(from + 1, f)};
        return intersect(t1, {0, 1, 2}, t2, {3, 4, 5});
    }
};

// The certified "separated at the shared corner" shortcut (a plane through the corner with
// each triangle strictly on its side) never hides an intersection: random sector pairs around
// one vertex, coplanar (a tilted plane z = x/2 + y/4, exact in binary) and off the plane,
// overlapping or not, give the answer of the exact tests alone.
TEST(TrianglesIntersect, SharedCornerShortcutAgreesWithTheExactTests) {
    std::mt19937_64 rng(26);
    std::uniform_real_distribution<double> angle(0.0, 6.283185307179586), radius(0.25, 2.0), lift(-1e-9, 1e-9);
    const Vec3d v{0.5, -0.25, 0.125};
    auto corner = [&](double t, double r, double off_plane) {
        const double x = std::ldexp(std::round(std::ldexp(r * std::cos(t), 20)), -20);
        const double y = std::ldexp(std::round(std::ldexp(r * std::sin(t), 20)), -20);
        return v + Vec3d{x, y, x / 2 + y / 4 + off_plane};
    };
    int intersecting = 0;
    for (int k = 0; k < 20000; ++k) {
        const double ta = angle(rng), tb = angle(rng), wa = 0.05 + 2.5 * angle(rng) / 6.3, wb = 0.05 + 2.5 * angle(rng) / 6.3;
        const bool planar = k % 2 == 0;
        const Vec3d a[3] = {v, corner(ta, radius(rng), 0), corner(ta + wa, radius(rng), planar ? 0 : lift(rng))};
        const Vec3d b[3] = {corner(tb, radius(rng), planar ? 0 : lift(rng)), v, corner(tb + wb, radius(rng), 0)};
        const bool exact = exact::segment_meets_triangle(b[2], b[0], a[0], a[1], a[2]) ||
                           exact::segment_meets_triangle(a[1], a[2], b[0], b[1], b[2]);
        ASSERT_EQ(triangles_intersect(a, {0, 1, 2}, b, {3, 0, 4}), exact) << "pair " << k;
        intersecting += exact;
    }
    EXPECT_GT(intersecting, 1000);  // both answers are exercised
    EXPECT_LT(intersecting, 19000);
}

TEST(TrianglesIntersect, EdgesOnOneLineAreJudgedExactly) {
    std::mt19937_64 random(22);
    auto on_grid = [&](double lo, double hi) {
        const double x = std::uniform_real_distribution<double>(lo, hi)(random);
        return std::ldexp(std::round(std::ldexp(x, 36)), -36);
    };
    auto vec = [&](double lo, double hi) { return Vec3d{on_grid(lo, hi), on_grid(lo, hi), on_grid(lo, hi)}; };
    int apart = 0, touching = 0, overlapping = 0;
    for (int i = 0; i < 2000; ++i) {
        const double base = i % 2 ? 1e4 : 1.0;
        const CollinearEdges c{vec(base, 2 * base), vec(-1, 1), vec(-1, 1), vec(-1, 1)};
        apart += c.meet(3);        // the edges [0, 2] and [3, 5]: a gap between them
        touching += c.meet(2);     // [0, 2] and [2, 4]: a corner on the other's corner
        overlapping += c.meet(1);  // [0, 2] and [1, 3]
    }
    EXPECT_EQ(apart, 0);
    EXPECT_EQ(touching, 2000);
    EXPECT_EQ(overlapping, 2000);
}

TriangleMesh concatenated(const TriangleMesh& a, const TriangleMesh& b) {
    TriangleMesh all = a;
    const int first = int(a.vertices.size());
    all.vertices.insert(all.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (const Int3& t : b.triangles) all.triangles.push_back({t.x + first, t.y + first, t.z + first});
    all.content_sha256.clear();
    return all;
}

TEST(SelfIntersections, ClosedShapesHaveNone) {
    for (const TriangleMesh& shape : {make_box({1, 2, 0.5}), make_icosphere(3), make_torus(1.0, 0.35, 32, 16), make_pawn(),
                                      make_soccer_ball(2)}) {
        const PreparedMesh m = prepare_mesh(shape);
        EXPECT_TRUE(m.report().intersections_checked);
        EXPECT_EQ(m.report().self_intersecting_pairs, 0) << shape.name;
        EXPECT_EQ(m.report().overlapping_shells, 0) << shape.name;
    }
}

TEST(SelfIntersections, OverlappingShellsAreCountedApartFromSelfIntersections) {
    const PreparedMesh overlapping = prepare_mesh(concatenated(make_box({1, 1, 1}), make_box({1, 1, 1}, {1, 0.5, 0.25})));
    EXPECT_EQ(overlapping.report().components, 2);
    EXPECT_EQ(overlapping.report().overlapping_shells, 1);
    EXPECT_GT(overlapping.report().shell_intersecting_pairs, 0);
    EXPECT_EQ(overlapping.report().self_intersecting_pairs, 0);
    EXPECT_EQ(overlapping.intersecting_triangles().size(), size_t(overlapping.report().shell_intersecting_pairs));

    const PreparedMesh nested = prepare_mesh(concatenated(make_box({1, 1, 1}), make_icosphere(2, 0.5)));
    EXPECT_EQ(nested.report().components, 2);
    EXPECT_EQ(nested.report().overlapping_shells, 0);
    EXPECT_EQ(nested.report().shell_intersecting_pairs, 0);
}

/// Every reported pair's triangles have overlapping boxes (triangles with disjoint boxes
/// cannot meet); returns how many pairs were checked.
size_t expect_boxes_overlap(const PreparedMesh& m) {
    auto box = [&](int t, int k, bool hi) {
        const Int3 v = m.triangles()[size_t(t)];
        const double a = m.vertices()[size_t(v.x)][k], b = m.vertices()[size_t(v.y)][k], c = m.vertices()[size_t(v.z)][k];
        return hi ? std::max({a, b, c}) : std::min({a, b, c});
    };
    for (const auto& [s, t] : m.intersecting_triangles())
        for (int k = 0; k < 3; ++k)
            EXPECT_TRUE(box(s, k, false) <= box(t, k, true) && box(t, k, false) <= box(s, k, true)) << s << " " << t;
    return m.intersecting_triangles().size();
}

TEST(SelfIntersections, OneShellFoldedThroughItself) {
    // A torus whose tube is thicker than its hole: the inner side crosses itself.
    const PreparedMesh m = prepare_mesh(make_torus(0.3, 0.5, 32, 16));
    EXPECT_EQ(m.report().components, 1);
    EXPECT_GT(m.report().self_intersecting_pairs, 0);
    EXPECT_GT(expect_boxes_overlap(m), 0u);
    bool warned = false;
    for (const std::string& w : m.warnings()) warned = warned || w.find("intersects itself") != std::string::npos;
    EXPECT_TRUE(warned);
}

TEST(SelfIntersections, TheSameListOnAnyNumberOfThreads) {
    // The descent is split into tasks that threads take in any order; the sorted list of
    // pairs must not depend on it (a torus through itself, two overlapping boxes).
    for (const PreparedMesh& m : {prepare_mesh(make_torus(0.3, 0.5, 32, 16)),
                                  prepare_mesh(concatenated(make_box({1, 1, 1}), make_box({1, 1, 1}, {1, 0.5, 0.25})))}) {
        const SelfIntersections one = find_self_intersections(m, *m.bvh(), m.shell_of(), 1);
        ASSERT_GT(one.pairs.size(), 0u);
        for (int threads : {2, 3, 8}) {
            const SelfIntersections many = find_self_intersections(m, *m.bvh(), m.shell_of(), threads);
            EXPECT_EQ(many.pairs, one.pairs) << threads << " threads";
            EXPECT_EQ(many.within_shell, one.within_shell);
            EXPECT_EQ(many.between_shells, one.between_shells);
            EXPECT_EQ(many.overlapping_shell_pairs, one.overlapping_shell_pairs);
        }
        EXPECT_EQ(one.pairs, m.intersecting_triangles());  // what preparation found, on all threads
    }
}

std::string find_data_file(const std::string& file) {
    const char* env = std::getenv("SDF_DATA_PATH");
    std::stringstream dirs(env ? env : "");
    for (std::string dir; std::getline(dirs, dir, ':');)
        if (!dir.empty() && std::filesystem::is_regular_file(std::filesystem::path(dir) / file))
            return (std::filesystem::path(dir) / file).string();
    return {};
}

TEST(SelfIntersectionsData, DragonLegacyHas25IntersectingPairs) {
    const std::string path = find_data_file("dragon-legacy.obj");
    if (path.empty()) GTEST_SKIP() << "dragon-legacy.obj not on SDF_DATA_PATH";
    const PreparedMesh m = prepare_mesh(load_mesh_file(path));
    EXPECT_EQ(m.report().components, 1);
    EXPECT_EQ(m.report().self_intersecting_pairs, 25);
    EXPECT_EQ(m.report().shell_intersecting_pairs, 0);
    // Two of them by file face index (1-based OBJ faces 5324/25178 and 48018/99756).
    EXPECT_EQ(m.source_triangle()[size_t(m.intersecting_triangles().front().first)], 5323);
    EXPECT_EQ(expect_boxes_overlap(m), 25u);
    const PreparedMesh dragon = prepare_mesh(load_mesh_file(find_data_file("dragon.obj")));
    EXPECT_EQ(dragon.report().self_intersecting_pairs, 0);
}

}  // namespace
}  // namespace sdf
