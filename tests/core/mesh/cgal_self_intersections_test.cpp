// The mesh report's self-intersection and overlapping-shell counts against CGAL's
// Polygon_mesh_processing::self_intersections (exact predicates) and connected_components,
// pair for pair: on the CAD-like models of tests/test_util/cad_models.h at every placement
// (planar faces as fans and strips over collinear points; none expected), on meshes with real
// intersections (interpenetrating CAD boxes, boxes with overlapping coplanar faces, a strip
// folded flat onto itself, a ribbon crossing itself, a torus thicker than its hole), and on
// the scans of SDF_DATA_PATH (bunny.obj; dragon-legacy.obj, 25 pairs; skipped when absent).
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <sstream>

#include "core/mesh/load_mesh.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "tests/test_util/cad_models.h"

namespace sdf {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Face = SurfaceMesh::Face_index;
namespace PMP = CGAL::Polygon_mesh_processing;

/// What the report says about intersections, or what CGAL finds.
struct Intersections {
    std::vector<std::pair<int, int>> pairs;  ///< prepared-mesh triangle ids, first < second, sorted
    int within_shell = 0, between_shells = 0, overlapping_shells = 0;
};

Intersections reported(const PreparedMesh& m) {
    EXPECT_TRUE(m.report().intersections_checked);
    return {m.intersecting_triangles(), m.report().self_intersecting_pairs, m.report().shell_intersecting_pairs,
            m.report().overlapping_shells};
}

/// CGAL's answer on the prepared mesh's triangles (face i of the Surface_mesh = triangle i).
Intersections cgal(const PreparedMesh& m) {
    SurfaceMesh sm;
    for (const Vec3d& p : m.vertices()) sm.add_vertex(Kernel::Point_3(p.x, p.y, p.z));
    for (const Int3& t : m.triangles()) {
        const Face f = sm.add_face(SurfaceMesh::Vertex_index(t.x), SurfaceMesh::Vertex_index(t.y),
                                   SurfaceMesh::Vertex_index(t.z));
        if (f == SurfaceMesh::null_face()) throw std::runtime_error(m.source() + ": CGAL's Surface_mesh refused a face");
    }
    std::vector<std::pair<Face, Face>> found;
    PMP::self_intersections(sm, std::back_inserter(found));
    auto shell = sm.add_property_map<Face, std::size_t>("f:shell").first;
    PMP::connected_components(sm, shell);

    Intersections out;
    std::set<std::pair<std::size_t, std::size_t>> shell_pairs;
    for (const auto& [f, g] : found) {
        const int a = int(f.idx()), b = int(g.idx());
        out.pairs.push_back({std::min(a, b), std::max(a, b)});
        if (shell[f] == shell[g]) {
            ++out.within_shell;
        } else {
            ++out.between_shells;
            shell_pairs.insert(std::minmax(shell[f], shell[g]));
        }
    }
    std::sort(out.pairs.begin(), out.pairs.end());
    out.overlapping_shells = int(shell_pairs.size());
    return out;
}

/// Ours equals CGAL's, pair for pair; returns the pairs found.
size_t expect_as_cgal(const PreparedMesh& m) {
    const Intersections ours = reported(m), theirs = cgal(m);
    EXPECT_EQ(ours.pairs, theirs.pairs) << m.source();
    EXPECT_EQ(ours.within_shell, theirs.within_shell) << m.source();
    EXPECT_EQ(ours.between_shells, theirs.between_shells) << m.source();
    EXPECT_EQ(ours.overlapping_shells, theirs.overlapping_shells) << m.source();
    return theirs.pairs.size();
}

TriangleMesh concatenated(const std::vector<TriangleMesh>& parts, const std::string& name) {
    TriangleMesh all;
    all.name = name;
    all.source = name;
    for (const TriangleMesh& m : parts) {
        const int first = int(all.vertices.size());
        all.vertices.insert(all.vertices.end(), m.vertices.begin(), m.vertices.end());
        for (const Int3& t : m.triangles) all.triangles.push_back({t.x + first, t.y + first, t.z + first});
    }
    return all;
}

TEST(SelfIntersectionsAsCgal, CadModelsAtEveryScaleOffsetAndRotationHaveNone) {
    int meshes = 0;
    for (const test::CadSolid& solid : test::cad_solids())
        for (const test::CadPlacement& place : test::cad_placements()) {
            const PreparedMesh m = prepare_mesh(test::cad_mesh(solid, place));
            ASSERT_TRUE(m.report().closed()) << m.source();
            ASSERT_EQ(m.report().components, 1) << m.source();
            ASSERT_EQ(m.report().degenerate_triangles, 0) << m.source();
            EXPECT_EQ(expect_as_cgal(m), 0u) << m.source();
            ++meshes;
        }
    EXPECT_EQ(meshes, 5 * 14);
}

/// The CAD solid `solid` placed by `place`, moved by `shift` grid units.
TriangleMesh shifted_cad(const test::CadSolid& solid, test::CadPlacement place, const Vec3d& shift) {
    place.offset = place.apply(shift);
    return test::cad_mesh(solid, place);
}

TEST(SelfIntersectionsAsCgal, InterpenetratingAndCoplanarOverlappingCadBoxes) {
    const test::CadSolid box = test::cad_solids().front();
    for (const test::CadPlacement& place : test::cad_placements()) {
        // Through each other (no two faces in one plane), then along x with the faces at
        // y = 0, y = 36, z = 0 and z = 24 overlapping in their planes. Odd shifts: the box's
        // grid points are even, so no vertex of one lands on a vertex of the other.
        for (const Vec3d& shift : {Vec3d{17, 11, 5}, Vec3d{25, 0, 0}}) {
            const PreparedMesh m =
                prepare_mesh(concatenated({test::cad_mesh(box, place), shifted_cad(box, place, shift)}, "two boxes, " + place.label));
            EXPECT_EQ(m.report().components, 2);
            EXPECT_GT(expect_as_cgal(m), 0u) << m.source();
            EXPECT_EQ(m.report().overlapping_shells, 1) << m.source();
        }
    }
}

/// A strip of unit quads along x in the plane z = 0 folded back flat onto itself (over the
/// edge at x = n), shifted a quarter unit across so that no vertex repeats: coplanar overlaps,
/// and the fold's two triangles share an edge with their third vertices on one side.
TriangleMesh folded_strip(int n, int back) {
    TriangleMesh m;
    m.name = m.source = "folded strip";
    for (int i = 0; i <= n; ++i) {
        m.vertices.push_back({double(i), 0, 0});
        m.vertices.push_back({double(i), 1, 0});
    }
    for (int i = 0; i < n; ++i) {
        const int b = 2 * i, t = b + 1;
        m.triangles.push_back({b, b + 2, t + 2});
        m.triangles.push_back({b, t + 2, t});
    }
    int b = 2 * n, t = b + 1;  // the fold edge
    for (int k = 1; k <= back; ++k) {
        const int nb = int(m.vertices.size()), nt = nb + 1;
        m.vertices.push_back({n - 0.5 - k, 0.25, 0});
        m.vertices.push_back({n - 0.5 - k, 1.25, 0});
        m.triangles.push_back({t, b, nb});
        m.triangles.push_back({t, nb, nt});
        b = nb;
        t = nt;
    }
    return m;
}

/// A vertical ribbon along a figure eight (open, so no vertex sits on the crossing).
TriangleMesh crossing_ribbon(int segments) {
    TriangleMesh m;
    m.name = m.source = "crossing ribbon";
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < segments; ++i) {
        const double a = 2 * pi * (i + 0.5) / (segments + 1);
        m.vertices.push_back({std::cos(a), std::sin(2 * a) / 2, 0});
        m.vertices.push_back({std::cos(a), std::sin(2 * a) / 2, 0.3});
    }
    for (int i = 0; i + 1 < segments; ++i) {
        const int b = 2 * i, t = b + 1;
        m.triangles.push_back({b, b + 2, t + 2});
        m.triangles.push_back({b, t + 2, t});
    }
    return m;
}

TEST(SelfIntersectionsAsCgal, FoldedAndCrossingStripsAndAThickTorus) {
    const PreparedMesh folded = prepare_mesh(folded_strip(8, 5));
    EXPECT_GT(expect_as_cgal(folded), 0u);
    EXPECT_GT(folded.report().self_intersecting_pairs, 0);
    const PreparedMesh ribbon = prepare_mesh(crossing_ribbon(24));
    EXPECT_GT(expect_as_cgal(ribbon), 0u);
    const PreparedMesh torus = prepare_mesh(make_torus(0.3, 0.5, 32, 16));
    EXPECT_GT(expect_as_cgal(torus), 0u);
    // And the closed procedural shapes have none.
    for (const TriangleMesh& shape : {make_box({1, 2, 0.5}), make_icosphere(3), make_pawn(), make_soccer_ball(2)})
        EXPECT_EQ(expect_as_cgal(prepare_mesh(shape)), 0u) << shape.name;
}

std::string find_data_file(const std::string& file) {
    const char* env = std::getenv("SDF_DATA_PATH");
    std::stringstream dirs(env ? env : "");
    for (std::string dir; std::getline(dirs, dir, ':');)
        if (!dir.empty() && std::filesystem::is_regular_file(std::filesystem::path(dir) / file))
            return (std::filesystem::path(dir) / file).string();
    return {};
}

TEST(SelfIntersectionsAsCgal, Scans) {
    const std::string bunny = find_data_file("bunny.obj"), legacy = find_data_file("dragon-legacy.obj");
    if (bunny.empty() || legacy.empty()) GTEST_SKIP() << "bunny.obj or dragon-legacy.obj not on SDF_DATA_PATH";
    expect_as_cgal(prepare_mesh(load_mesh_file(bunny)));
    EXPECT_EQ(expect_as_cgal(prepare_mesh(load_mesh_file(legacy))), 25u);
}

}  // namespace
}  // namespace sdf
