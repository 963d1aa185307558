// Polygon faces: one triangulation for every format (polygon_triangulation.h).
//  - Random star-shaped and comb polygons in tilted planes: n - 2 triangles that keep the
//    polygon's orientation, cover its shoelace area exactly once and use every polygon edge
//    once.
//  - An L-shaped prism (concave hexagon caps, written starting at a corner whose fan would
//    cover the notch), a box with collinear corners (T-junction free only if the corner
//    stays a vertex), and a cube with one corner lifted (three non-planar quads), each
//    written as OBJ, OFF, ASCII and binary PLY and ASCII STL by writers of this file: every
//    format reads to the same triangles, a closed mesh without self-intersections, and
//    distances equal to the analytic ones (L prism) and to each other (2,000 points).
//  - Issue 38: the grid clipper gives the triangles of the quadratic one it replaced
//    (reference_ear_clipping.h) on random simple, comb, keyhole, collinear and
//    self-crossing polygons; a 40,000-corner star and comb are triangulated (29 s before) and stop
//    on request; polygons of 10,000..40,000 corners that cross themselves (random corners,
//    a circle wound three times, a star polygon, a figure of eight) triangulate as chains
//    whose winding numbers are the polygon's at random points (crossing counts) and stop on
//    request; a cylinder with 300-corner caps reads alike in every format, its centre
//    inside (OBJ corners beyond 255: tinyobjloader's unsigned char count), and an OFF
//    polygon on the last line is not taken for a truncated file.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/mesh/load_mesh.h"
#include "core/mesh/polygon_triangulation.h"
#include "core/mesh/prepared_mesh.h"
#include "core/parallel/task_monitor.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "tests/core/mesh/mesh_file_writers.h"
#include "tests/core/mesh/reference_ear_clipping.h"
#include "tests/test_util/scratch_dir.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- triangulate_polygon on its own ------------------------------------------------------

/// A polygon given by 2-D points placed in the plane spanned by `e1`, `e2` through `origin`.
struct PlanarPolygon {
    std::vector<Vec3d> vertices;
    std::vector<int> corners;
    double area = 0;  ///< shoelace, in the plane's 2-D coordinates (unit e1, e2)
    Vec3d normal;     ///< e1 x e2
};

PlanarPolygon place(const std::vector<std::pair<double, double>>& uv, Vec3d origin, Vec3d e1, Vec3d e2) {
    PlanarPolygon p;
    p.normal = cross(e1, e2);
    for (size_t i = 0; i < uv.size(); ++i) {
        p.vertices.push_back(origin + e1 * uv[i].first + e2 * uv[i].second);
        p.corners.push_back(int(i));
        const auto& a = uv[i];
        const auto& b = uv[(i + 1) % uv.size()];
        p.area += 0.5 * (a.first * b.second - b.first * a.second);
    }
    return p;
}

/// Checks the triangulation of `p`: n - 2 triangles, each turning the polygon's way (the
/// sign of its shoelace area) with positive area, areas summing to the polygon's, every polygon edge used exactly once in
/// its own direction and every other edge (a cut) once in each direction.
void expect_valid_triangulation(const PlanarPolygon& p, const std::string& what) {
    std::vector<Int3> tris;
    PolygonStats stats;
    triangulate_polygon(p.vertices, p.corners, tris, stats);
    const size_t n = p.corners.size();
    ASSERT_EQ(tris.size(), n - 2) << what;
    EXPECT_EQ(stats.not_simple, 0) << what;
    EXPECT_EQ(stats.non_planar, 0) << what;
    double area = 0;
    std::map<std::pair<int, int>, int> directed;
    for (const Int3& t : tris) {
        const Vec3d a = p.vertices[size_t(t.x)], b = p.vertices[size_t(t.y)], c = p.vertices[size_t(t.z)];
        const double signed_area = 0.5 * dot(cross(b - a, c - a), p.normal) * (p.area < 0 ? -1 : 1);
        EXPECT_GT(signed_area, 0) << what;
        area += signed_area;
        for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
    }
    EXPECT_NEAR(area, std::abs(p.area), 1e-12 * std::abs(p.area)) << what;
    for (size_t i = 0; i < n; ++i) {
        const int a = int(i), b = int((i + 1) % n);
        EXPECT_EQ(directed.count({a, b}) ? directed.at({a, b}) : 0, 1) << what << ": polygon edge " << a << "-" << b;
        EXPECT_EQ(directed.count({b, a}), 0u) << what << ": polygon edge " << a << "-" << b << " reversed";
    }
    for (const auto& [edge, count] : directed) {
        const bool polygon_edge = edge.second == (edge.first + 1) % int(n);
        const auto reversed = directed.find({edge.second, edge.first});
        if (!polygon_edge) {
            EXPECT_EQ(count, 1) << what << ": cut " << edge.first << "-" << edge.second;
            EXPECT_TRUE(reversed != directed.end() && reversed->second == 1) << what << ": cut " << edge.first << "-" << edge.second;
        }
    }
}

TEST(TriangulatePolygon, RandomStarShapedPolygonsInTiltedPlanes) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 300; ++trial) {
        const int n = 4 + int(rng() % 40);
        std::vector<std::pair<double, double>> uv;
        for (int i = 0; i < n; ++i) {
            const double angle = 2 * kPi * (i + 0.8 * u(rng)) / n;
            const double r = 0.2 + u(rng);
            uv.push_back({r * std::cos(angle), r * std::sin(angle)});
        }
        const Vec3d e1 = normalize_or_zero(Vec3d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
        const Vec3d e2 = normalize_or_zero(cross(Vec3d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5}, e1));
        expect_valid_triangulation(place(uv, {u(rng) * 100, -50, 3}, e1, e2), "trial " + std::to_string(trial));
    }
}

TEST(TriangulatePolygon, ConvexCapOfThousandsOfCorners) {
    std::vector<std::pair<double, double>> uv;
    for (int i = 0; i < 5000; ++i) uv.push_back({std::cos(2 * kPi * i / 5000), std::sin(2 * kPi * i / 5000)});
    expect_valid_triangulation(place(uv, {1e3, 2e3, -3e3}, {0, 1, 0}, {0, 0, 1}), "circle");
}

TEST(TriangulatePolygon, CombWithManyReflexCornersAndReversedOrientation) {
    // A comb of 8 teeth (24 reflex-heavy corners), written clockwise in the xz plane.
    std::vector<std::pair<double, double>> uv = {{0, 0}, {16, 0}};
    for (int k = 7; k >= 0; --k) {
        uv.push_back({2.0 * k + 2, 3});
        uv.push_back({2.0 * k + 1.5, 3});
        uv.push_back({2.0 * k + 1.5, 1});
        uv.push_back({2.0 * k + 1, 1});
    }
    uv.pop_back();
    uv.pop_back();
    uv.push_back({0, 3});
    expect_valid_triangulation(place(uv, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}), "comb");
    std::reverse(uv.begin(), uv.end());
    expect_valid_triangulation(place(uv, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}), "reversed comb");
}

TEST(TriangulatePolygon, QuadsAlongTheShorterDiagonalRectanglesAsFans) {
    const std::vector<Vec3d> v = {{0, 0, 0}, {2, -0.5, 0}, {4, 0, 0}, {2, 0.5, 0}};
    std::vector<Int3> tris;
    PolygonStats stats;
    triangulate_polygon(v, {0, 1, 2, 3}, tris, stats);  // the 1-3 diagonal is shorter
    ASSERT_EQ(tris.size(), 2u);
    EXPECT_EQ(tris[0], (Int3{1, 2, 3}));  // the ear at corner 2 (corner 0 ranks last among equal cuts)
    EXPECT_EQ(tris[1], (Int3{0, 1, 3}));
    tris.clear();
    const std::vector<Vec3d> square = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    triangulate_polygon(square, {0, 1, 2, 3}, tris, stats);  // equal diagonals: the fan from corner 0
    ASSERT_EQ(tris.size(), 2u);
    EXPECT_EQ(tris[0], (Int3{0, 1, 2}));
    EXPECT_EQ(tris[1], (Int3{0, 2, 3}));
    EXPECT_EQ(stats.polygons, 2);
}

TEST(TriangulatePolygon, CollinearCornersStayVerticesWithoutZeroAreaTriangles) {
    // A rectangle with two corners on its bottom edge and one on its top edge.
    const std::vector<Vec3d> v = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {3, 1, 0}, {1.5, 1, 0}, {0, 1, 0}};
    std::vector<Int3> tris;
    PolygonStats stats;
    triangulate_polygon(v, {0, 1, 2, 3, 4, 5, 6}, tris, stats);
    ASSERT_EQ(tris.size(), 5u);
    std::vector<int> uses(v.size(), 0);
    for (const Int3& t : tris) {
        EXPECT_GT(length(cross(v[size_t(t.y)] - v[size_t(t.x)], v[size_t(t.z)] - v[size_t(t.x)])), 0.0);
        for (int k = 0; k < 3; ++k) ++uses[size_t(t[k])];
    }
    for (size_t i = 0; i < v.size(); ++i) EXPECT_GT(uses[i], 0) << "corner " << i << " lost";
}

TEST(TriangulatePolygon, RepeatedCornersAndPolygonsWithoutArea) {
    const std::vector<Vec3d> v = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1, 1, 0}, {2, 0, 0}};
    std::vector<Int3> tris;
    PolygonStats stats;
    triangulate_polygon(v, {0, 1, 2, 4, 3}, tris, stats);  // 4 repeats 2's position: a quad
    EXPECT_EQ(tris.size(), 2u);
    EXPECT_EQ(stats.not_simple, 0);
    tris.clear();
    triangulate_polygon(v, {0, 1, 5, 1}, tris, stats);  // all on the x axis: no area
    EXPECT_EQ(stats.not_simple, 1);
    for (const Int3& t : tris)
        EXPECT_EQ(length(cross(v[size_t(t.y)] - v[size_t(t.x)], v[size_t(t.z)] - v[size_t(t.x)])), 0.0);
}

/// Triangulates `p` with the clipper and with the quadratic reference: the same triangles
/// in the same order, and the same counts.
void expect_reference_triangles(const std::vector<Vec3d>& v, const std::string& what) {
    std::vector<int> corners(v.size());
    for (size_t i = 0; i < v.size(); ++i) corners[i] = int(i);
    std::vector<Int3> fast, slow;
    PolygonStats fast_stats, slow_stats;
    triangulate_polygon(v, corners, fast, fast_stats);
    reference::triangulate_polygon(v, corners, slow, slow_stats);
    ASSERT_EQ(fast.size(), slow.size()) << what;
    for (size_t i = 0; i < fast.size(); ++i) ASSERT_EQ(fast[i], slow[i]) << what << ": triangle " << i;
    EXPECT_EQ(fast_stats.not_simple, slow_stats.not_simple) << what;
    EXPECT_EQ(fast_stats.non_planar, slow_stats.non_planar) << what;
}

std::vector<Vec3d> in_plane(const std::vector<std::pair<double, double>>& uv, Vec3d origin, Vec3d e1, Vec3d e2) {
    return place(uv, origin, e1, e2).vertices;
}

TEST(TriangulatePolygon, SameTrianglesAsTheQuadraticClipper) {
    std::mt19937_64 rng(38);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const auto tilted = [&] {
        const Vec3d e1 = normalize_or_zero(Vec3d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5});
        return std::make_pair(e1, normalize_or_zero(cross(Vec3d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5}, e1)));
    };
    for (int trial = 0; trial < 400; ++trial) {
        const int n = 4 + int(rng() % (trial < 300 ? 60 : 700));
        std::vector<std::pair<double, double>> uv;
        const int kind = trial % 5;
        for (int i = 0; i < n; ++i) {
            const double angle = 2 * kPi * (i + (kind == 1 ? 0.0 : 0.8 * u(rng))) / n;
            double r = 0.2 + u(rng);
            if (kind == 1) r = i % 2 ? 1.0 : 0.5;                    // a regular star: ties of every kind
            if (kind == 2) r = std::round(r * 4) / 4;                // radii on a grid: collinear corners
            uv.push_back({r * std::cos(angle), r * std::sin(angle)});
            if (kind == 3) uv.back() = {std::round(uv.back().first * 8) / 8, std::round(uv.back().second * 8) / 8};
        }
        if (kind == 4) {  // a polygon that crosses itself: corners anywhere
            for (auto& q : uv) q = {u(rng), u(rng)};
        }
        const auto [e1, e2] = tilted();
        expect_reference_triangles(in_plane(uv, {u(rng) * 100, -50, 3}, e1, e2), "trial " + std::to_string(trial));
        if (::testing::Test::HasFatalFailure()) return;
    }
    // Combs of many teeth, both orientations, and a keyhole (a corner visited twice).
    for (int teeth : {3, 40, 300}) {
        std::vector<std::pair<double, double>> uv = {{0, 0}, {2.0 * teeth, 0}};
        for (int k = teeth - 1; k >= 0; --k)
            for (const auto& q : {std::pair{2.0 * k + 2, 3.0}, {2.0 * k + 1.5, 3.0}, {2.0 * k + 1.5, 1.0}, {2.0 * k + 1, 1.0}})
                uv.push_back(q);
        uv.resize(uv.size() - 2);
        uv.push_back({0, 3});
        expect_reference_triangles(in_plane(uv, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}), "comb " + std::to_string(teeth));
        std::reverse(uv.begin(), uv.end());
        expect_reference_triangles(in_plane(uv, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}), "reversed comb " + std::to_string(teeth));
    }
    const std::vector<std::pair<double, double>> keyhole = {{0, 0}, {4, 0}, {4, 4}, {0, 4}, {0, 2}, {1, 2},
                                                            {1, 3}, {3, 3}, {3, 1}, {1, 1}, {1, 2}, {0, 2}};
    expect_reference_triangles(in_plane(keyhole, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}), "keyhole");
}

/// A star of n corners, every other one reflex.
std::vector<Vec3d> star(int n) {
    std::vector<Vec3d> v;
    for (int i = 0; i < n; ++i) {
        const double r = i % 2 ? 1.0 : 0.9, angle = 2 * kPi * i / n;
        v.push_back({r * std::cos(angle), r * std::sin(angle), 0.25});
    }
    return v;
}

TEST(TriangulatePolygon, FortyThousandCornersAndAStopRequest) {
    // The quadratic clipper took 29 s for one such polygon; no timing is asserted here
    // (benchmarks measure speed), the suite's time limit would show a relapse.
    std::vector<std::pair<double, double>> uv;
    for (const Vec3d& q : star(40000)) uv.push_back({q.x, q.y});
    expect_valid_triangulation(place(uv, {5, 6, 7}, {0, 1, 0}, {1, 0, 0}), "40,000-corner star");
    // A comb of 10,000 teeth: its base corners' ears span the whole comb, past every tooth.
    uv = {{0, 0}, {20000, 0}};
    for (int k = 9999; k >= 0; --k)
        for (const auto& q : {std::pair{2.0 * k + 2, 3.0}, {2.0 * k + 1.5, 3.0}, {2.0 * k + 1.5, 1.0}, {2.0 * k + 1, 1.0}})
            uv.push_back(q);
    uv.resize(uv.size() - 2);
    uv.push_back({0, 3});
    expect_valid_triangulation(place(uv, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}), "40,001-corner comb");
    // A stop request (Ctrl-C in Python) ends the clipping.
    const std::vector<Vec3d> v = star(40000);
    std::vector<int> corners(v.size());
    for (size_t i = 0; i < v.size(); ++i) corners[i] = int(i);
    TaskMonitor monitor;
    monitor.request_stop();
    ScopedTaskMonitor scope(&monitor);
    std::vector<Int3> tris;
    PolygonStats stats;
    EXPECT_THROW(triangulate_polygon(v, corners, tris, stats), TaskStopped);
}

/// Winding number of the closed polygon `uv` around q (Sunday's crossing rule: upward edges
/// with q strictly left count +1, downward edges with q strictly right -1).
int polygon_winding(const std::pair<double, double>* uv, size_t n, std::pair<double, double> q) {
    int w = 0;
    for (size_t i = 0; i < n; ++i) {
        const auto& a = uv[i];
        const auto& b = uv[(i + 1) % n];
        const double side = (b.first - a.first) * (q.second - a.second) - (q.first - a.first) * (b.second - a.second);
        if (a.second <= q.second && b.second > q.second && side > 0) ++w;
        if (a.second > q.second && b.second <= q.second && side < 0) --w;
    }
    return w;
}

/// Checks the triangles of a polygon that crosses itself, as chains: n - 2 triangles of the
/// polygon's own corners, their signed areas summing to the polygon's shoelace area, every
/// polygon edge used once in its own direction and every cut once in each direction (so the
/// triangles' boundary is the polygon), and at `probes` random points of the polygon's box
/// the sum of the triangles' windings equal to the polygon's winding number, computed
/// independently by crossing counts. Returns the seconds the triangulation took (printed,
/// never asserted).
double expect_chain_triangulation(const std::vector<std::pair<double, double>>& uv, const std::string& what,
                                  int probes = 300) {
    const PlanarPolygon p = place(uv, {0.5, -2, 7}, {0, 0, 1}, {1, 0, 0});
    std::vector<Int3> tris;
    PolygonStats stats;
    const auto start = std::chrono::steady_clock::now();
    triangulate_polygon(p.vertices, p.corners, tris, stats);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const size_t n = uv.size();
    EXPECT_EQ(tris.size(), n - 2) << what;
    EXPECT_EQ(stats.not_simple, 1) << what;
    // Signed areas in the (u, v) of `uv` (the placement maps u to z and v to x: a proper rotation).
    const auto orient = [&](int a, int b, int c) {
        const auto &pa = uv[size_t(a)], &pb = uv[size_t(b)], &pc = uv[size_t(c)];
        return (pb.first - pa.first) * (pc.second - pa.second) - (pb.second - pa.second) * (pc.first - pa.first);
    };
    double area = 0, magnitude = 0;
    std::map<std::pair<int, int>, int> directed;
    for (const Int3& t : tris) {
        EXPECT_TRUE(t.x >= 0 && t.y >= 0 && t.z >= 0 && size_t(std::max({t.x, t.y, t.z})) < n) << what;
        area += 0.5 * orient(t.x, t.y, t.z);
        magnitude += 0.5 * std::abs(orient(t.x, t.y, t.z));
        for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
    }
    EXPECT_NEAR(area, p.area, 1e-9 * magnitude) << what;
    for (size_t i = 0; i < n; ++i) {
        const std::pair<int, int> e{int(i), int((i + 1) % n)};
        const std::pair<int, int> reversed{e.second, e.first};
        EXPECT_EQ(directed[e] - directed[reversed], 1) << what << ": polygon edge " << e.first;
    }
    for (const auto& [e, count] : directed) {
        if (e.second == (e.first + 1) % int(n) || e.first == (e.second + 1) % int(n)) continue;
        const std::pair<int, int> reversed{e.second, e.first};
        EXPECT_EQ(count, directed[reversed]) << what << ": cut " << e.first << "-" << e.second;
    }
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (const auto& q : uv) {
        lo[0] = std::min(lo[0], q.first); hi[0] = std::max(hi[0], q.first);
        lo[1] = std::min(lo[1], q.second); hi[1] = std::max(hi[1], q.second);
    }
    std::mt19937_64 rng(n);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int nonzero = 0;
    for (int k = 0; k < probes; ++k) {
        const std::pair<double, double> q{lo[0] + (hi[0] - lo[0]) * u(rng), lo[1] + (hi[1] - lo[1]) * u(rng)};
        int sum = 0;
        for (const Int3& t : tris) {
            const std::pair<double, double> tri[3] = {uv[size_t(t.x)], uv[size_t(t.y)], uv[size_t(t.z)]};
            sum += polygon_winding(tri, 3, q);
        }
        const int want = polygon_winding(uv.data(), uv.size(), q);
        nonzero += want != 0;
        EXPECT_EQ(sum, want) << what << ": probe " << k << " at (" << q.first << ", " << q.second << ")";
    }
    EXPECT_GT(nonzero, 0) << what;
    std::cout << what << ": " << n << " corners, " << tris.size() << " triangles in " << seconds << " s\n";
    return seconds;
}

// Issue 38: polygons that cross themselves ran out of ears again and again, and each time the
// fallback scanned every corner (and corners turned reflex went to a list scanned by every ear
// test): quadratic. Now their triangles are checked as chains whose winding is the polygon's
// everywhere, on 10,000..40,001 corners: random corners, a circle wound three times, a star
// polygon {n/k} and a figure of eight. A small one still gets the quadratic clipper's triangles.
TEST(TriangulatePolygon, LargePolygonsThatCrossThemselves) {
    std::mt19937_64 rng(3838);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<std::pair<double, double>> uv;
    for (int i = 0; i < 10000; ++i) uv.push_back({u(rng), u(rng)});
    expect_chain_triangulation(uv, "10,000 random corners", 100);
    uv.clear();
    for (int i = 0; i < 20000; ++i) {  // three turns, radius wobbling so that the turns cross
        const double angle = 3 * 2 * kPi * i / 20000, r = 1 + 0.2 * std::sin(7.3 * angle) + 0.01 * u(rng);
        uv.push_back({r * std::cos(angle), r * std::sin(angle)});
    }
    expect_chain_triangulation(uv, "a circle wound three times");
    uv.clear();
    for (int i = 0; i < 40001; ++i) {  // {40001/137}: each edge crosses many others
        const double angle = 2 * kPi * double((int64_t(i) * 137) % 40001) / 40001;
        uv.push_back({std::cos(angle) * (1 + 1e-3 * u(rng)), std::sin(angle)});
    }
    expect_chain_triangulation(uv, "a star polygon {40001/137}", 40);
    uv.clear();
    for (int i = 0; i < 20000; ++i) {  // a figure of eight: winding +1 in one lobe, -1 in the other
        const double t = 2 * kPi * i / 20000;
        uv.push_back({std::sin(t), std::sin(t) * std::cos(t) + 1e-4 * u(rng)});
    }
    expect_chain_triangulation(uv, "a figure of eight");
    // The quadratic clipper's triangles on a self-crossing polygon larger than those of
    // SameTrianglesAsTheQuadraticClipper.
    std::vector<Vec3d> v;
    for (int i = 0; i < 1500; ++i) v.push_back({u(rng), 0.25, u(rng)});
    expect_reference_triangles(v, "1,500 random corners");
    // A stop request ends a self-crossing polygon's clipping too.
    std::vector<int> corners(v.size());
    for (size_t i = 0; i < v.size(); ++i) corners[i] = int(i);
    for (int i = 0; i < 8192; ++i) { v.push_back({u(rng), 0.25, u(rng)}); corners.push_back(int(v.size()) - 1); }
    TaskMonitor monitor;
    monitor.request_stop();
    ScopedTaskMonitor scope(&monitor);
    std::vector<Int3> tris;
    PolygonStats stats;
    EXPECT_THROW(triangulate_polygon(v, corners, tris, stats), TaskStopped);
}

// ---- the same polygons in every format ----------------------------------------------------

struct PolygonMesh {
    std::vector<Vec3d> vertices;
    std::vector<std::vector<int>> faces;
};

std::string obj_of(const PolygonMesh& m) {
    std::string s;
    for (const Vec3d& p : m.vertices) s += "v " + test::g17(p.x) + " " + test::g17(p.y) + " " + test::g17(p.z) + "\n";
    for (const auto& f : m.faces) {
        s += "f";
        for (int i : f) s += " " + std::to_string(i + 1);
        s += "\n";
    }
    return s;
}

std::string off_of(const PolygonMesh& m) {
    std::string s = "OFF\n" + std::to_string(m.vertices.size()) + " " + std::to_string(m.faces.size()) + " 0\n";
    for (const Vec3d& p : m.vertices) s += test::g17(p.x) + " " + test::g17(p.y) + " " + test::g17(p.z) + "\n";
    for (const auto& f : m.faces) {
        s += std::to_string(f.size());
        for (int i : f) s += " " + std::to_string(i);
        s += "\n";
    }
    return s;
}

std::string ply_of(const PolygonMesh& m, bool binary) {
    size_t largest = 0;
    for (const auto& f : m.faces) largest = std::max(largest, f.size());
    const bool wide = largest > 255;  // a count beyond uchar: uint
    std::string s = std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") + " 1.0\nelement vertex " +
                    std::to_string(m.vertices.size()) +
                    "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
                    std::to_string(m.faces.size()) + "\nproperty list " + (wide ? "uint" : "uchar") +
                    " int vertex_indices\nend_header\n";
    for (const Vec3d& p : m.vertices) {
        if (!binary) s += test::g17(p.x) + " " + test::g17(p.y) + " " + test::g17(p.z) + "\n";
        else for (int k = 0; k < 3; ++k) test::put<double>(s, p[k], false);
    }
    for (const auto& f : m.faces) {
        if (!binary) {
            s += std::to_string(f.size());
            for (int i : f) s += " " + std::to_string(i);
            s += "\n";
        } else {
            if (wide) test::put<uint32_t>(s, uint32_t(f.size()), false);
            else test::put<uint8_t>(s, uint8_t(f.size()), false);
            for (int i : f) test::put<int32_t>(s, i, false);
        }
    }
    return s;
}

/// ASCII STL with polygon facets (the reader takes 3 or more vertices per loop).
std::string stl_of(const PolygonMesh& m) {
    std::string s = "solid polygons\n";
    for (const auto& f : m.faces) {
        s += "facet normal 0 0 0\nouter loop\n";
        for (int i : f) {
            const Vec3d& p = m.vertices[size_t(i)];
            s += "vertex " + test::g17(p.x) + " " + test::g17(p.y) + " " + test::g17(p.z) + "\n";
        }
        s += "endloop\nendfacet\n";
    }
    return s + "endsolid polygons\n";
}

/// A prism over the counter-clockwise polygon `ring` (x, y) from z = 0 to z = 1.
PolygonMesh prism(const std::vector<std::pair<double, double>>& ring) {
    PolygonMesh m;
    const int n = int(ring.size());
    for (double z : {0.0, 1.0})
        for (const auto& [x, y] : ring) m.vertices.push_back({x, y, z});
    std::vector<int> bottom, top;
    for (int k = 0; k < n; ++k) {
        bottom.push_back((n - k) % n);  // clockwise from below: outward -z, starting at corner 0
        top.push_back(n + k);
        m.faces.push_back({k, (k + 1) % n, n + (k + 1) % n, n + k});
    }
    m.faces.push_back(bottom);
    m.faces.push_back(top);
    return m;
}

class PolygonFormats : public test::ScratchDirTest {
protected:
    PolygonFormats() : ScratchDirTest("sdf_polygon_formats") {}

    /// The mesh read back from each format, in a fixed order: obj, off, ply, binary ply, stl.
    std::vector<std::pair<std::string, TriangleMesh>> read_every_format(const PolygonMesh& m) {
        const std::vector<std::pair<std::string, std::string>> files = {
            {"m.obj", obj_of(m)}, {"m.off", off_of(m)}, {"m.ply", ply_of(m, false)}, {"b.ply", ply_of(m, true)}, {"m.stl", stl_of(m)}};
        std::vector<std::pair<std::string, TriangleMesh>> out;
        for (const auto& [name, text] : files) out.push_back({name, load_mesh_file(write(name, text))});
        return out;
    }

    /// Every format gives the triangles of the OBJ (by position: STL welds its own vertex ids).
    static void expect_same_triangles(const std::vector<std::pair<std::string, TriangleMesh>>& read) {
        const TriangleMesh& obj = read[0].second;
        for (const auto& [name, mesh] : read) {
            ASSERT_EQ(mesh.triangles.size(), obj.triangles.size()) << name;
            for (size_t i = 0; i < obj.triangles.size(); ++i)
                for (int k = 0; k < 3; ++k)
                    ASSERT_EQ(mesh.vertices[size_t(mesh.triangles[i][k])], obj.vertices[size_t(obj.triangles[i][k])])
                        << name << " triangle " << i << " corner " << k;
            EXPECT_EQ(mesh.polygon_stats.polygons, obj.polygon_stats.polygons) << name;
            EXPECT_EQ(mesh.polygon_stats.non_planar, obj.polygon_stats.non_planar) << name;
        }
    }

    static void expect_closed_and_clean(const PreparedMesh& m, const std::string& name) {
        EXPECT_EQ(m.report().boundary_edges, 0) << name;
        EXPECT_EQ(m.report().nonmanifold_edges, 0) << name;
        EXPECT_EQ(m.report().degenerate_triangles, 0) << name;
        EXPECT_EQ(m.report().self_intersecting_pairs, 0) << name;
        EXPECT_TRUE(m.report().sign_reliable()) << name;
    }

    static std::vector<PointSample> distances(const PreparedMesh& mesh, const std::vector<Vec3d>& points) {
        SamplerOptions o;
        o.precision = Precision::Double;
        o.progress = false;
        o.threads = 1;
        return make_cpu_brute_force_sampler(o)->bind(share(mesh))->query(points);
    }
};

TEST_F(PolygonFormats, ConcaveHexagonCapsGiveTheLShapedPrismInEveryFormat) {
    // The L's corner 0 is (2, 0): a fan from it would cover the notch [1,2] x [1,2].
    const PolygonMesh l = prism({{2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 0}});
    const auto read = read_every_format(l);
    expect_same_triangles(read);
    // Analytic distances to the L prism: above the notch, in its middle, inside.
    const std::vector<Vec3d> points = {{1.2, 1.3, 1.1}, {1.5, 1.5, 0.5}, {0.5, 0.5, 0.5}, {1.8, 0.5, 0.25}};
    const std::vector<double> truth = {std::sqrt(0.05), 0.5, -0.5, -0.2};
    for (const auto& [name, mesh] : read) {
        const PreparedMesh prepared = prepare_mesh(mesh);
        expect_closed_and_clean(prepared, name);
        EXPECT_EQ(mesh.polygon_stats.polygons, 8) << name;  // 6 sides and 2 caps
        EXPECT_EQ(mesh.polygon_stats.non_planar, 0) << name;
        const std::vector<PointSample> d = distances(prepared, points);
        for (size_t i = 0; i < points.size(); ++i) EXPECT_NEAR(d[i].distance, truth[i], 1e-14) << name << " point " << i;
    }
}

TEST_F(PolygonFormats, CollinearCornersLeaveNoTJunction) {
    // A 2 x 1 x 1 box whose front (y = 0) is two quads meeting at x = 1, so the bottom and
    // top are pentagons with a corner in the middle of their front edge.
    PolygonMesh m;
    m.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0},   // bottom: 0..4
                  {0, 0, 1}, {1, 0, 1}, {2, 0, 1}, {2, 1, 1}, {0, 1, 1}};  // top: 5..9
    m.faces = {{1, 0, 4, 3, 2},  // bottom (-z), starting at the collinear corner
               {5, 6, 7, 8, 9},  // top (+z)
               {0, 1, 6, 5}, {1, 2, 7, 6},  // front halves (-y)
               {2, 3, 8, 7},                // right (+x)
               {3, 4, 9, 8},                // back (+y)
               {4, 0, 5, 9}};               // left (-x)
    const auto read = read_every_format(m);
    expect_same_triangles(read);
    for (const auto& [name, mesh] : read) {
        const PreparedMesh prepared = prepare_mesh(mesh);
        expect_closed_and_clean(prepared, name);
        EXPECT_NEAR(prepared.report().signed_volume, 2.0, 1e-15) << name;
    }
}

TEST_F(PolygonFormats, NonPlanarQuadsAreCutAlikeAndReported) {
    // A unit cube with corner (1, 1, 1) moved out to (1.2, 1.3, 1.25): the top and the two
    // side quads through it are non-planar.
    PolygonMesh m = prism({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
    m.vertices[6] = {1.2, 1.3, 1.25};
    const auto read = read_every_format(m);
    expect_same_triangles(read);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-0.5, 1.5);
    std::vector<Vec3d> points(2000);
    for (Vec3d& p : points) p = {u(rng), u(rng), u(rng)};
    std::vector<PointSample> reference;
    for (const auto& [name, mesh] : read) {
        EXPECT_EQ(mesh.polygon_stats.non_planar, 3) << name;
        EXPECT_GT(mesh.polygon_stats.max_non_planarity, 0.01) << name;
        const PreparedMesh prepared = prepare_mesh(mesh);
        expect_closed_and_clean(prepared, name);
        bool warned = false;
        for (const std::string& w : prepared.warnings()) warned |= w.find("3 non-planar polygons") != std::string::npos;
        EXPECT_TRUE(warned) << name;
        const std::vector<PointSample> d = distances(prepared, points);
        if (reference.empty()) { reference = d; continue; }
        for (size_t i = 0; i < points.size(); ++i) ASSERT_EQ(d[i].distance, reference[i].distance) << name << " point " << i;
    }
}

TEST_F(PolygonFormats, CylinderWithCapsOf300CornersInEveryFormat) {
    // Radius 1, z in [0, 1]: the centre is 0.5 from both caps and 1 from the side. OBJ read
    // it outside (+0.9998: tinyobjloader counted the caps' 300 corners as 44).
    std::vector<std::pair<double, double>> ring;
    for (int k = 0; k < 300; ++k) ring.push_back({std::cos(2 * kPi * k / 300), std::sin(2 * kPi * k / 300)});
    const auto read = read_every_format(prism(ring));
    expect_same_triangles(read);
    const std::vector<Vec3d> points = {{0, 0, 0.5}, {0, 0, 1.25}, {0.1, -0.2, 0.1}};
    const std::vector<double> truth = {-0.5, 0.25, -0.1};
    for (const auto& [name, mesh] : read) {
        EXPECT_EQ(mesh.triangles.size(), 2u * 300 + 2u * 298) << name;
        const PreparedMesh prepared = prepare_mesh(mesh);
        expect_closed_and_clean(prepared, name);
        const std::vector<PointSample> d = distances(prepared, points);
        for (size_t i = 0; i < points.size(); ++i) EXPECT_NEAR(d[i].distance, truth[i], 1e-12) << name << " point " << i;
    }
    // 256 corners: tinyobjloader's count 0 ("face has 0 vertices").
    ring.resize(256);
    for (int k = 0; k < 256; ++k) ring[size_t(k)] = {std::cos(2 * kPi * k / 256), std::sin(2 * kPi * k / 256)};
    expect_same_triangles(read_every_format(prism(ring)));
}

TEST_F(PolygonFormats, OffPolygonOnTheLastLineLongerThanTheBytesAfterIt) {
    // The 65-gon cap is the file's last line: 65 corners, fewer bytes after its line.
    std::vector<std::pair<double, double>> ring;
    for (int k = 0; k < 65; ++k) ring.push_back({std::cos(2 * kPi * k / 65), std::sin(2 * kPi * k / 65)});
    const PolygonMesh m = prism(ring);
    const TriangleMesh mesh = load_mesh_file(write("cap.off", off_of(m)));
    EXPECT_EQ(mesh.triangles.size(), 2u * 65 + 2u * 63);
    // A count its line cannot hold is still refused before anything is allocated.
    const std::string bad = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n";
    try {
        load_mesh_file(write("bad.off", bad));
        ADD_FAILURE() << "a face of 2e9 corners on a short line was read";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("more than its line holds"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace sdf
