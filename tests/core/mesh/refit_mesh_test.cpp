// refit_prepared_mesh(): a deforming mesh of the same topology against prepare_mesh() of the
// moved vertices, the independent truth: every array, report count, buffer, search bound,
// BVH node and intersecting pair byte for byte, on several deformations of meshes with welds,
// degenerate and unreferenced parts, boundaries, several shells, an outward flip that comes
// and goes, and a weld tolerance; and the refusals where the new positions would weld or drop
// otherwise, each naming the vertex or triangle.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/bvh/triangle_bvh.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/mesh/vertex_welding.h"

namespace sdf {
namespace {

template <typename V>
bool same_bytes(const V& a, const V& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
}

bool same_double(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

template <typename T>
void expect_same_buffers(const MeshBuffers<T>& a, const MeshBuffers<T>& b) {
    EXPECT_TRUE(same_bytes(a.vertices, b.vertices));
    EXPECT_TRUE(same_bytes(a.face_normals, b.face_normals));
    EXPECT_TRUE(same_bytes(a.edge_normals, b.edge_normals));
    EXPECT_TRUE(same_bytes(a.vertex_normals, b.vertex_normals));
    EXPECT_TRUE(same_bytes(a.triangles, b.triangles));
    EXPECT_TRUE(same_bytes(a.packed, b.packed));
    EXPECT_EQ(std::memcmp(&a.box_lo, &b.box_lo, sizeof(a.box_lo)), 0);
    EXPECT_EQ(std::memcmp(&a.box_hi, &b.box_hi, sizeof(a.box_hi)), 0);
}

/// Everything a sampler reads of a prepared mesh, and its report, equal byte for byte.
void expect_same_mesh(const PreparedMesh& a, const PreparedMesh& b) {
    EXPECT_EQ(a.name(), b.name());
    EXPECT_EQ(a.source(), b.source());
    EXPECT_EQ(a.content_sha256(), b.content_sha256());
    EXPECT_TRUE(same_bytes(a.vertices(), b.vertices()));
    EXPECT_TRUE(same_bytes(a.triangles(), b.triangles()));
    EXPECT_TRUE(same_bytes(a.source_triangle(), b.source_triangle()));
    EXPECT_TRUE(same_bytes(a.input_vertices(), b.input_vertices()));
    EXPECT_TRUE(same_bytes(a.input_triangles(), b.input_triangles()));
    EXPECT_TRUE(same_bytes(a.face_normals(), b.face_normals()));
    EXPECT_TRUE(same_bytes(a.edge_normals(), b.edge_normals()));
    EXPECT_TRUE(same_bytes(a.vertex_normals(), b.vertex_normals()));
    EXPECT_TRUE(same_bytes(a.shell_of(), b.shell_of()));
    EXPECT_EQ(a.intersecting_triangles(), b.intersecting_triangles());
    EXPECT_EQ(std::memcmp(&a.bounds(), &b.bounds(), sizeof(Bounds3)), 0);
    expect_same_buffers(a.buffers<float>(), b.buffers<float>());
    expect_same_buffers(a.buffers<double>(), b.buffers<double>());
    const FloatSearchBound& x = a.search_bound();
    const FloatSearchBound& y = b.search_bound();
    EXPECT_TRUE(same_double(x.rho, y.rho) && same_double(x.two_l, y.two_l) && same_double(x.coordinate, y.coordinate) &&
                same_double(x.rho_double, y.rho_double) && same_double(x.sliver_reach_float, y.sliver_reach_float) &&
                x.usable == y.usable);
    const MeshReport &r = a.report(), &s = b.report();
    EXPECT_EQ(r.input_vertices, s.input_vertices);
    EXPECT_EQ(r.input_triangles, s.input_triangles);
    EXPECT_EQ(r.welded_vertices, s.welded_vertices);
    EXPECT_EQ(r.unreferenced_vertices, s.unreferenced_vertices);
    EXPECT_EQ(r.degenerate_triangles, s.degenerate_triangles);
    EXPECT_EQ(r.boundary_edges, s.boundary_edges);
    EXPECT_EQ(r.nonmanifold_edges, s.nonmanifold_edges);
    EXPECT_EQ(r.inconsistent_edges, s.inconsistent_edges);
    EXPECT_EQ(r.components, s.components);
    EXPECT_TRUE(same_double(r.signed_volume, s.signed_volume)) << r.signed_volume << " " << s.signed_volume;
    EXPECT_EQ(r.flipped, s.flipped);
    EXPECT_EQ(r.intersections_checked, s.intersections_checked);
    EXPECT_EQ(r.self_intersecting_pairs, s.self_intersecting_pairs);
    EXPECT_EQ(r.shell_intersecting_pairs, s.shell_intersecting_pairs);
    EXPECT_EQ(r.overlapping_shells, s.overlapping_shells);
    EXPECT_EQ(a.warnings(), b.warnings());
    // The tree the samplers search: the same build of the same bytes.
    const auto ta = a.bvh(), tb = b.bvh();
    EXPECT_TRUE(same_bytes(ta->nodes, tb->nodes));
    EXPECT_TRUE(same_bytes(ta->triangle_index, tb->triangle_index));
    EXPECT_TRUE(same_bytes(ta->packed_float, tb->packed_float));
    EXPECT_TRUE(same_bytes(ta->packed_double, tb->packed_double));
}

MeshPreparationOptions refittable(double weld_tolerance = 0.0, bool detect_intersections = true) {
    MeshPreparationOptions o;
    o.keep_input = true;
    o.keep_topology = true;
    o.weld_tolerance = weld_tolerance;
    o.detect_intersections = detect_intersections;
    return o;
}

TriangleMesh moved_by(const TriangleMesh& mesh, const std::function<Vec3d(const Vec3d&)>& f) {
    TriangleMesh m = mesh;
    for (Vec3d& v : m.vertices) v = f(v);
    m.content_sha256.clear();
    return m;
}

/// The deformations every case is refitted with, one after another.
std::vector<std::function<Vec3d(const Vec3d&)>> deformations() {
    return {
        [](const Vec3d& v) { return v * 1.25 + Vec3d(0.125, -0.5, 2.0); },  // scale and shift
        [](const Vec3d& v) {  // a rotation about z by 0.7 rad
            const double c = std::cos(0.7), s = std::sin(0.7);
            return Vec3d(c * v.x - s * v.y, s * v.x + c * v.y, v.z);
        },
        [](const Vec3d& v) { return v + Vec3d(0.05 * std::sin(3 * v.y), 0.04 * std::cos(2 * v.x), 0.03 * std::sin(5 * v.x)); },
        [](const Vec3d& v) { return Vec3d(2.0 * v.x, 0.5 * v.y, v.z + 0.3 * v.x * v.x); },  // a bend
    };
}

/// Refits `mesh` through every deformation in turn (each refit from the last) and checks
/// each against a fresh preparation of the moved vertices.
void expect_refits_equal_fresh(const TriangleMesh& mesh, const MeshPreparationOptions& options) {
    PreparedMesh current = prepare_mesh(mesh, options);
    ASSERT_TRUE(current.refittable());
    TriangleMesh moved = mesh;
    int step = 0;
    for (const auto& f : deformations()) {
        SCOPED_TRACE(mesh.name + ", deformation " + std::to_string(step++));
        moved = moved_by(moved, f);
        const PreparedMesh refitted = refit_prepared_mesh(current, moved);
        const PreparedMesh fresh = prepare_mesh(moved, options);
        expect_same_mesh(refitted, fresh);
        EXPECT_TRUE(refitted.refittable());
        current = refitted;
    }
}

TriangleMesh separate_triangles(const TriangleMesh& mesh) {
    TriangleMesh soup;
    soup.name = mesh.name + "-soup";
    soup.source = "test";
    for (const Int3& t : mesh.triangles) {
        const int first = int(soup.vertices.size());
        for (int k = 0; k < 3; ++k) soup.vertices.push_back(mesh.vertices[size_t(t[k])]);
        soup.triangles.push_back({first, first + 1, first + 2});
    }
    return soup;
}

constexpr size_t kBoxSoupVertices = 36;  // 12 triangles, 3 corners each

/// A box written as a triangle soup (welded back), with a degenerate triangle (a repeated
/// vertex), a collinear one (its corners share x and y, which every deformation above keeps
/// equal), an unreferenced vertex, and a second shell: a torus above the box.
TriangleMesh every_case_mesh() {
    TriangleMesh m = separate_triangles(make_box({0.5, 0.5, 0.5}));
    const TriangleMesh torus = make_torus(0.6, 0.15, 16, 8);
    const int offset = int(m.vertices.size());
    for (const Vec3d& v : torus.vertices) m.vertices.push_back(v + Vec3d(0.0, 0.0, 2.0));
    for (const Int3& t : torus.triangles) m.triangles.push_back({t.x + offset, t.y + offset, t.z + offset});
    m.triangles.push_back({0, 0, 1});  // repeated vertex
    const int a = int(m.vertices.size());
    m.vertices.push_back({3, 3, 0});
    m.vertices.push_back({3, 3, 1});
    m.vertices.push_back({3, 3, 2.5});
    m.vertices.push_back({9, 9, 9});  // unreferenced
    m.triangles.push_back({a, a + 1, a + 2});
    m.name = "every-case";
    return m;
}

TEST(RefitMesh, EqualsAFreshPreparationOnEveryDeformation) {
    expect_refits_equal_fresh(separate_triangles(make_torus(1.0, 0.35, 24, 12)), refittable());
    expect_refits_equal_fresh(make_icosphere(3), refittable(0.0, false));  // the BVH built on first use
    TriangleMesh open = make_box();
    open.triangles.pop_back();
    open.triangles.pop_back();
    open.name = "open-box";
    expect_refits_equal_fresh(open, refittable());
}

TEST(RefitMesh, KeepsDegenerateUnreferencedAndIntersectingParts) {
    const TriangleMesh mesh = every_case_mesh();
    const PreparedMesh apart = prepare_mesh(mesh, refittable());
    ASSERT_EQ(apart.report().degenerate_triangles, 2);
    ASSERT_EQ(apart.report().unreferenced_vertices, 4);  // the collinear triangle's corners and the lone vertex
    ASSERT_EQ(apart.report().components, 2);
    ASSERT_EQ(apart.report().shell_intersecting_pairs, 0);
    expect_refits_equal_fresh(mesh, refittable());
    // The torus lowered into the box: the shells intersect now, and the refit's check says so.
    TriangleMesh lowered = mesh;
    for (size_t v = kBoxSoupVertices; v < kBoxSoupVertices + make_torus(0.6, 0.15, 16, 8).vertices.size(); ++v)
        lowered.vertices[v] -= Vec3d(0.0, 0.0, 2.0);
    lowered.content_sha256.clear();
    const PreparedMesh fresh = prepare_mesh(lowered, refittable());
    ASSERT_GT(fresh.report().shell_intersecting_pairs, 0);
    const PreparedMesh into = refit_prepared_mesh(apart, lowered);
    expect_same_mesh(into, fresh);
    expect_same_mesh(refit_prepared_mesh(into, mesh), apart);  // and out again
}

TEST(RefitMesh, FollowsTheOutwardFlipBothWays) {
    const TriangleMesh outward = separate_triangles(make_torus(1.0, 0.35, 24, 12));
    const TriangleMesh mirrored = moved_by(outward, [](const Vec3d& v) { return Vec3d(-v.x, v.y, v.z); });
    const PreparedMesh a = prepare_mesh(outward, refittable());
    ASSERT_FALSE(a.report().flipped);
    const PreparedMesh inward = refit_prepared_mesh(a, mirrored);  // turned inside out: flipped, as fresh
    EXPECT_TRUE(inward.report().flipped);
    expect_same_mesh(inward, prepare_mesh(mirrored, refittable()));
    const PreparedMesh back = refit_prepared_mesh(inward, outward);  // and back
    EXPECT_FALSE(back.report().flipped);
    expect_same_mesh(back, prepare_mesh(outward, refittable()));
}

TEST(RefitMesh, KeepsTheWeldTolerance) {
    // Each corner written out per triangle, 1e-9 apart: welded within 1e-6, before and after.
    TriangleMesh soup = separate_triangles(make_icosphere(2));
    for (size_t v = 0; v < soup.vertices.size(); ++v) soup.vertices[v] += Vec3d(1e-9 * double(v % 3), 0.0, 0.0);
    const MeshPreparationOptions o = refittable(1e-6);
    ASSERT_GT(prepare_mesh(soup, o).report().welded_vertices, 0);
    expect_refits_equal_fresh(soup, o);
}

std::string refit_error(const PreparedMesh& mesh, const TriangleMesh& moved) {
    try {
        refit_prepared_mesh(mesh, moved);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}

void expect_refused(const PreparedMesh& mesh, const TriangleMesh& moved, const std::string& why) {
    const std::string e = refit_error(mesh, moved);
    EXPECT_NE(e.find(why), std::string::npos) << e;
    EXPECT_NE(e.find("prepare the moved mesh anew"), std::string::npos) << e;
}

TEST(RefitMesh, RefusesNewPositionsThatWeldOrDropOtherwise) {
    const TriangleMesh soup = separate_triangles(make_box());
    const PreparedMesh box = prepare_mesh(soup, refittable());
    // A copy of a corner moved off the others: no longer welded.
    size_t copy = 1, first = 0;
    for (bool found = false; !found; ++copy)
        for (first = 0; first < copy && !found; ++first) found = soup.vertices[first] == soup.vertices[copy];
    --copy, --first;
    TriangleMesh apart = soup;
    apart.vertices[copy] += Vec3d(1e-3, 0, 0);
    expect_refused(box, apart,
                   "input vertex " + std::to_string(copy) + " was welded to input vertex " + std::to_string(first) +
                       " when the mesh was prepared and is a vertex of its own at the new positions (weld_tolerance 0)");
    // Two corners moved onto one another: a weld the first preparation did not make (and two
    // triangles degenerate).
    const TriangleMesh plain = make_box();
    const PreparedMesh welded = prepare_mesh(plain, refittable());
    TriangleMesh collapsed = plain;
    collapsed.vertices[7] = collapsed.vertices[5];
    expect_refused(welded, collapsed, "input vertex 7 was a vertex of its own when the mesh was prepared and is welded to input vertex 5");
    // A corner moved onto the line of its triangle's other two: newly degenerate.
    TriangleMesh flat = plain;
    const Int3 t = plain.triangles[3];
    flat.vertices[size_t(t.z)] = (plain.vertices[size_t(t.x)] + plain.vertices[size_t(t.y)]) * 0.5;
    EXPECT_NE(refit_error(welded, flat).find("is degenerate (collinear corners) at the new positions and was not"),
              std::string::npos)
        << refit_error(welded, flat);
    // The other way: a collinear triangle, dropped, bent out of line.
    const TriangleMesh cases = every_case_mesh();
    const PreparedMesh kept = prepare_mesh(cases, refittable());
    const size_t last = cases.triangles.size() - 1;
    TriangleMesh bent = cases;
    bent.vertices[bent.vertices.size() - 3] += Vec3d(0.0, 0.5, 0.0);  // the collinear triangle's middle corner
    expect_refused(kept, bent,
                   "input triangle " + std::to_string(last) +
                       " is not degenerate (collinear corners) at the new positions and was when the mesh was prepared");
    // Other counts, other triangles, no kept topology.
    TriangleMesh fewer = plain;
    fewer.vertices.pop_back();
    expect_refused(welded, fewer, "expected 8 vertices (one per input vertex), got 7");
    TriangleMesh other = plain;
    std::swap(other.triangles[0].x, other.triangles[0].y);
    expect_refused(welded, other, "the triangles differ from the input's");
    expect_refused(prepare_mesh(plain), plain, "it was prepared without keep_topology");
}

// The refit's quick check of a tolerance-0 welding against the welding itself.
TEST(RefitMesh, TheWeldCheckAgreesWithTheWelding) {
    std::mt19937 rng(5);
    std::uniform_int_distribution<int> pick(0, 40);
    std::vector<Vec3d> in;
    for (int i = 0; i < 2000; ++i) {  // 41 distinct positions, each many times; 0.0 and -0.0 among them
        const int k = pick(rng);
        in.push_back(k == 0 ? Vec3d(-0.0, 0.0, 0.0) : k == 1 ? Vec3d(0.0, 0.0, 0.0) : Vec3d(0.5 * k, 1.0 / k, -double(k)));
    }
    std::vector<Vec3d> welded, quick;
    const std::vector<int> weld = weld_vertices(in, 0.0, welded);
    ASSERT_EQ(welded.size(), 40u);  // -0.0 and 0.0 compare equal: one vertex
    ASSERT_TRUE(welds_like(in, weld, quick, 2));
    EXPECT_TRUE(same_bytes(quick, welded));
    for (int trial = 0; trial < 20; ++trial) {
        std::vector<Vec3d> moved = in;
        const size_t i = size_t(rng() % in.size());
        moved[i] = Vec3d(100.0 + trial, 0.0, 0.0);  // off its group (or a group of its own moved)
        std::vector<Vec3d> a, b;
        const bool same = weld_vertices(moved, 0.0, a) == weld;
        EXPECT_EQ(welds_like(moved, weld, b, 2), same) << trial;
    }
    std::vector<Vec3d> merged = in, scratch;
    for (Vec3d& p : merged)
        if (p == Vec3d(0.5 * 7, 1.0 / 7, -7.0)) p = Vec3d(0.5 * 9, 1.0 / 9, -9.0);  // two groups now at one position
    EXPECT_FALSE(welds_like(merged, weld, scratch, 2));
    std::vector<Vec3d> nan = in;
    nan[3].y = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(welds_like(nan, weld, scratch, 2));
}

}  // namespace
}  // namespace sdf
