// prepare_mesh(): angle-weighted pseudonormals against values known in closed form (box
// corners and edges), welding, dropping degenerate triangles, and the reports and warnings
// for open, inward and inconsistently oriented meshes; the same bytes at every thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"

namespace sdf {
namespace {

constexpr double kExact = 1e-14;  // closed-form unit vectors, a few roundings away

void expect_near(const Vec3d& got, const Vec3d& want, double tolerance) {
    EXPECT_NEAR(got.x, want.x, tolerance);
    EXPECT_NEAR(got.y, want.y, tolerance);
    EXPECT_NEAR(got.z, want.z, tolerance);
}

bool any_warning_contains(const PreparedMesh& m, const std::string& text) {
    for (const std::string& w : m.warnings())
        if (w.find(text) != std::string::npos) return true;
    return false;
}

/// The same triangles with every vertex written out again for each use (a "triangle soup").
TriangleMesh as_separate_triangles(const TriangleMesh& mesh) {
    TriangleMesh soup;
    soup.name = mesh.name + "-soup";
    for (const Int3& t : mesh.triangles) {
        const int first = int(soup.vertices.size());
        for (int k = 0; k < 3; ++k) soup.vertices.push_back(mesh.vertices[size_t(t[k])]);
        soup.triangles.push_back({first, first + 1, first + 2});
    }
    return soup;
}

TriangleMesh reversed(TriangleMesh mesh, size_t first, size_t count) {
    for (size_t i = first; i < first + count; ++i) std::swap(mesh.triangles[i].y, mesh.triangles[i].z);
    mesh.content_sha256.clear();
    return mesh;
}

TEST(PreparedMesh, PseudonormalsAreUnitLength) {
    for (const TriangleMesh& mesh : {make_box({1.0, 2.0, 0.5}), make_icosphere(2), make_torus(1.0, 0.35, 16, 8),
                                     make_pawn(), make_soccer_ball(1)}) {
        const PreparedMesh m = prepare_mesh(mesh);
        ASSERT_EQ(m.face_normals().size(), m.triangles().size());
        ASSERT_EQ(m.edge_normals().size(), 3 * m.triangles().size());
        ASSERT_EQ(m.vertex_normals().size(), m.vertices().size());
        for (const auto* normals : {&m.face_normals(), &m.edge_normals(), &m.vertex_normals()})
            for (const Vec3d& n : *normals) ASSERT_NEAR(length(n), 1.0, 1e-12) << mesh.name;
    }
}

// Each of the three faces at a corner contributes its normal times a right angle, however its
// two triangles split that angle, so the pseudonormal is (+-1, +-1, +-1)/sqrt(3) even for a
// box that is not a cube.
TEST(PreparedMesh, BoxCornerPseudonormalsPointAlongTheDiagonals) {
    const Vec3d center{0.5, -0.25, 2.0};
    const PreparedMesh m = prepare_mesh(make_box({1.0, 2.0, 0.5}, center));
    ASSERT_EQ(m.vertices().size(), 8u);
    const double s = 1.0 / std::sqrt(3.0);
    for (size_t i = 0; i < m.vertices().size(); ++i) {
        const Vec3d d = m.vertices()[i] - center;
        expect_near(m.vertex_normals()[i], Vec3d{d.x > 0 ? s : -s, d.y > 0 ? s : -s, d.z > 0 ? s : -s}, kExact);
    }
}

// Along a box edge the pseudonormal is the normalised sum of the two face normals; along a
// face's diagonal both triangles share the face normal.
TEST(PreparedMesh, BoxEdgePseudonormalsAreNormalisedSumsOfFaceNormals) {
    const PreparedMesh m = prepare_mesh(make_box({1.0, 2.0, 0.5}));
    ASSERT_EQ(m.triangles().size(), 12u);
    // Face normals of the box, from which coordinate its three corners share.
    std::vector<Vec3d> axis_normal;
    for (const Int3& t : m.triangles()) {
        const Vec3d a = m.vertices()[size_t(t.x)], b = m.vertices()[size_t(t.y)], c = m.vertices()[size_t(t.z)];
        Vec3d n(0.0);
        for (int k = 0; k < 3; ++k)
            if (a[k] == b[k] && b[k] == c[k]) n[k] = a[k] > 0 ? 1.0 : -1.0;
        axis_normal.push_back(n);
    }
    std::map<std::pair<int, int>, std::vector<int>> faces_of_edge;
    for (size_t i = 0; i < m.triangles().size(); ++i)
        for (int e = 0; e < 3; ++e)
            faces_of_edge[std::minmax(m.triangles()[i][e], m.triangles()[i][(e + 1) % 3])].push_back(int(i));
    ASSERT_EQ(faces_of_edge.size(), 18u);  // 12 box edges, 6 face diagonals
    int box_edges = 0;
    for (size_t i = 0; i < m.triangles().size(); ++i) {
        expect_near(m.face_normals()[i], axis_normal[i], kExact);
        for (int e = 0; e < 3; ++e) {
            const std::vector<int>& f = faces_of_edge.at(std::minmax(m.triangles()[i][e], m.triangles()[i][(e + 1) % 3]));
            ASSERT_EQ(f.size(), 2u);
            const Vec3d sum = axis_normal[size_t(f[0])] + axis_normal[size_t(f[1])];
            box_edges += sum != axis_normal[i] * 2.0;
            expect_near(m.edge_normals()[3 * i + size_t(e)], sum / length(sum), kExact);
        }
    }
    EXPECT_EQ(box_edges, 2 * 12);  // each box edge seen from both of its triangles
}

TEST(PreparedMesh, WeldsBitIdenticalVerticesIntoAClosedMesh) {
    const TriangleMesh box = make_box({1.0, 2.0, 0.5});
    const PreparedMesh m = prepare_mesh(as_separate_triangles(box));
    EXPECT_EQ(m.report().input_vertices, 36);
    EXPECT_EQ(m.report().welded_vertices, 28);
    EXPECT_EQ(m.vertices().size(), 8u);
    EXPECT_EQ(m.triangles().size(), 12u);
    EXPECT_TRUE(m.report().closed());
    EXPECT_TRUE(m.report().consistently_oriented());
    EXPECT_EQ(m.report().components, 1);
    EXPECT_NEAR(m.report().signed_volume, 8.0, kExact);
    EXPECT_TRUE(m.warnings().empty());
}

TEST(PreparedMesh, WeldsSeparatedSpheresAndKeepsTheirPseudonormals) {
    const TriangleMesh sphere = make_icosphere(2);
    const PreparedMesh welded = prepare_mesh(as_separate_triangles(sphere));
    const PreparedMesh direct = prepare_mesh(sphere);
    ASSERT_EQ(welded.vertices().size(), direct.vertices().size());
    EXPECT_TRUE(welded.report().sign_reliable());
    // Welding keeps first-use order, so compare by position.
    std::map<std::tuple<double, double, double>, Vec3d> normal_at;
    for (size_t i = 0; i < direct.vertices().size(); ++i)
        normal_at[{direct.vertices()[i].x, direct.vertices()[i].y, direct.vertices()[i].z}] = direct.vertex_normals()[i];
    for (size_t i = 0; i < welded.vertices().size(); ++i)
        expect_near(welded.vertex_normals()[i],
                    normal_at.at({welded.vertices()[i].x, welded.vertices()[i].y, welded.vertices()[i].z}), kExact);
}

TEST(PreparedMesh, DropsDegenerateTrianglesAndMapsTheRestToTheirSource) {
    TriangleMesh mesh = make_box();
    const int corner0 = 0, corner1 = 1;  // the edge from (-1,-1,-1) to (1,-1,-1)
    const int midpoint = int(mesh.vertices.size());
    mesh.vertices.push_back((mesh.vertices[corner0] + mesh.vertices[corner1]) * 0.5);
    // Input order: box 0..3, repeated index, box 4..8, zero area (collinear), box 9..11.
    std::vector<Int3> triangles(mesh.triangles.begin(), mesh.triangles.begin() + 4);
    triangles.push_back({corner0, corner0, corner1});
    triangles.insert(triangles.end(), mesh.triangles.begin() + 4, mesh.triangles.begin() + 9);
    triangles.push_back({corner0, midpoint, corner1});
    triangles.insert(triangles.end(), mesh.triangles.begin() + 9, mesh.triangles.end());
    mesh.triangles = triangles;
    mesh.content_sha256.clear();

    const PreparedMesh m = prepare_mesh(mesh);
    EXPECT_EQ(m.report().input_triangles, 14);
    EXPECT_EQ(m.report().degenerate_triangles, 2);
    EXPECT_EQ(m.report().unreferenced_vertices, 1);  // the midpoint, used only by a dropped triangle
    ASSERT_EQ(m.triangles().size(), 12u);
    EXPECT_EQ(m.source_triangle(), (std::vector<int>{0, 1, 2, 3, 5, 6, 7, 8, 9, 11, 12, 13}));
    for (size_t i = 0; i < m.triangles().size(); ++i)
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(m.vertices()[size_t(m.triangles()[i][k])],
                      mesh.vertices[size_t(mesh.triangles[size_t(m.source_triangle()[i])][k])]);
    EXPECT_TRUE(m.report().sign_reliable());
    EXPECT_TRUE(any_warning_contains(m, "degenerate"));
}

// Slivers thinner than the search's rounding (kRoundingSliverHeight of the extent) make the
// pseudonormal sign unreliable, so `auto` takes the winding sign: the fanned tetrahedron's
// fan down to 2^-45 (a point beside its sharp edge got the wrong side) has them, down to
// 2^-30 (every side right, also 10^4 from the origin) it does not.
TEST(PreparedMesh, SliversWithinTheSearchsRoundingMakeTheSignUnreliable) {
    for (const Vec3d offset : {Vec3d{0, 0, 0}, Vec3d{1e4, 1e4, 1e4}}) {
        const PreparedMesh thin = prepare_mesh(test::fanned_tetrahedron(offset, 45));
        EXPECT_GT(thin.report().slivers_within_rounding, 0) << offset.x;
        EXPECT_FALSE(thin.report().sign_reliable()) << offset.x;
        EXPECT_NE(thin.report().sign_unreliable_reason().find("slivers thinner than"), std::string::npos);
        EXPECT_TRUE(any_warning_contains(thin, "slivers thinner than the nearest-triangle search's rounding"));
    }
    for (const Vec3d offset : {Vec3d{0, 0, 0}, Vec3d{1e4, 1e4, 1e4}}) {
        const PreparedMesh fan30 = prepare_mesh(test::fanned_tetrahedron(offset, 30));
        EXPECT_EQ(fan30.report().slivers_within_rounding, 0) << offset.x;
        EXPECT_TRUE(fan30.report().sign_reliable()) << fan30.report().sign_unreliable_reason();
    }
    EXPECT_EQ(prepare_mesh(test::make_sliver_sphere()).report().slivers_within_rounding, 0);
    EXPECT_EQ(prepare_mesh(make_icosphere(3)).report().slivers_within_rounding, 0);
}

TEST(PreparedMesh, OpenBoxReportsItsBoundaryAndWarns) {
    TriangleMesh mesh = make_box();
    mesh.triangles.pop_back();
    mesh.content_sha256.clear();
    const PreparedMesh m = prepare_mesh(mesh);
    EXPECT_EQ(m.report().boundary_edges, 3);
    EXPECT_EQ(m.report().nonmanifold_edges, 0);
    EXPECT_FALSE(m.report().closed());
    EXPECT_FALSE(m.report().sign_reliable());
    EXPECT_FALSE(m.report().flipped);
    EXPECT_TRUE(any_warning_contains(m, "open"));
}

TEST(PreparedMesh, InwardMeshIsFlippedOutwardWithAWarning) {
    const TriangleMesh outward = make_icosphere(1);
    const PreparedMesh m = prepare_mesh(reversed(outward, 0, outward.triangles.size()));
    EXPECT_TRUE(m.report().flipped);
    EXPECT_TRUE(m.report().sign_reliable());
    EXPECT_GT(m.report().signed_volume, 0.0);
    EXPECT_NEAR(m.report().signed_volume, prepare_mesh(outward).report().signed_volume, 1e-12);
    // The flipped triangles are the original ones, and their normals point outward.
    for (size_t i = 0; i < m.triangles().size(); ++i) {
        const Int3 t = m.triangles()[i];
        const Vec3d& a = m.vertices()[size_t(t.x)];
        EXPECT_GT(dot(m.face_normals()[i], a), 0.0);
        EXPECT_GT(dot(m.vertex_normals()[size_t(t.x)], a), 0.0);
        for (int e = 0; e < 3; ++e) EXPECT_GT(dot(m.edge_normals()[3 * i + size_t(e)], a), 0.0);
    }
    EXPECT_TRUE(any_warning_contains(m, "flipped"));

    MeshPreparationOptions keep;
    keep.orient_outward = false;
    const PreparedMesh kept = prepare_mesh(reversed(outward, 0, outward.triangles.size()), keep);
    EXPECT_FALSE(kept.report().flipped);
    EXPECT_LT(kept.report().signed_volume, 0.0);
}

TEST(PreparedMesh, OneReversedTriangleIsReportedAsInconsistent) {
    const PreparedMesh m = prepare_mesh(reversed(make_icosphere(1), 7, 1));
    EXPECT_EQ(m.report().inconsistent_edges, 3);
    EXPECT_TRUE(m.report().closed());
    EXPECT_FALSE(m.report().consistently_oriented());
    EXPECT_FALSE(m.report().sign_reliable());
    EXPECT_FALSE(m.report().flipped);
    EXPECT_TRUE(any_warning_contains(m, "not consistently oriented"));
}

TEST(PreparedMesh, CountsComponents) {
    TriangleMesh two = make_box();
    const TriangleMesh other = make_box({0.5, 0.5, 0.5}, {5.0, 0.0, 0.0});
    for (const Int3& t : other.triangles) two.triangles.push_back({t.x + 8, t.y + 8, t.z + 8});
    two.vertices.insert(two.vertices.end(), other.vertices.begin(), other.vertices.end());
    two.content_sha256.clear();
    const PreparedMesh m = prepare_mesh(two);
    EXPECT_EQ(m.report().components, 2);
    EXPECT_NEAR(m.report().signed_volume, 8.0 + 1.0, kExact);
}

TEST(PreparedMesh, WeldsWithinATolerance) {
    TriangleMesh soup = as_separate_triangles(make_box());
    for (size_t i = 0; i < soup.vertices.size(); i += 2) soup.vertices[i] += Vec3d{1e-9, -1e-9, 1e-9};
    MeshPreparationOptions options;
    options.weld_tolerance = 1e-6;
    const PreparedMesh m = prepare_mesh(soup, options);
    EXPECT_EQ(m.vertices().size(), 8u);
    EXPECT_TRUE(m.report().sign_reliable());
    EXPECT_NEAR(m.report().signed_volume, 8.0, 1e-6);
}

// Two copies of a vertex 1e-7 apart but on either side of a grid-cell boundary (x = 0.75 =
// 1.5 cells of 0.5) must merge: closeness, not grid alignment, decides.
TEST(PreparedMesh, WeldsVerticesCloserThanTheToleranceAcrossGridCells) {
    TriangleMesh soup = as_separate_triangles(make_box({0.75, 0.75, 0.75}));
    for (Vec3d& v : soup.vertices)
        if (v == Vec3d{0.75, 0.75, 0.75}) {
            v.x -= 1e-7;
            break;
        }
    MeshPreparationOptions options;
    options.weld_tolerance = 0.5;
    const PreparedMesh m = prepare_mesh(soup, options);
    EXPECT_EQ(m.vertices().size(), 8u);
    EXPECT_TRUE(m.report().closed());
}

/// An icosphere, an inward torus, a fan of triangles sharing one edge (non-manifold), a
/// random soup over shared vertices (boundary, inconsistent and non-manifold edges, -0 and
/// +0 coordinates) and some degenerate triangles: one mesh with every case of preparation.
TriangleMesh every_case_mesh() {
    TriangleMesh m = make_icosphere(4, 1.0, {3, 0, 0});
    auto append = [&](const TriangleMesh& part) {
        const int first = int(m.vertices.size());
        m.vertices.insert(m.vertices.end(), part.vertices.begin(), part.vertices.end());
        for (const Int3& t : part.triangles) m.triangles.push_back({t.x + first, t.y + first, t.z + first});
    };
    append(reversed(make_torus(1.0, 0.3, 48, 24), 0, 48 * 24 * 2));
    const int fan = int(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {{0, 0, -2}, {1, 0, -2}, {0, 1, -2}, {0, -1, -2}, {0, 0, -1}, {0, 0, -3}});
    for (int k = 2; k < 6; ++k) m.triangles.push_back({fan, fan + 1, fan + k});
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    // A fan of 48 triangles around one vertex, in shuffled order, some reversed: a vertex with
    // more uses than the adjacency's insertion sort takes (it merge-sorts those).
    const int hub = int(m.vertices.size());
    m.vertices.push_back({0, 0, 4});
    for (int k = 0; k < 48; ++k) m.vertices.push_back({std::cos(k * 0.1309), std::sin(k * 0.1309), 4.0 + 0.01 * (k % 3)});
    std::vector<Int3> fan_triangles;
    for (int k = 0; k < 48; ++k) {
        const int a = hub + 1 + k, b = hub + 1 + (k + 1) % 48;
        fan_triangles.push_back(k % 5 == 0 ? Int3{hub, b, a} : Int3{hub, a, b});
    }
    std::shuffle(fan_triangles.begin(), fan_triangles.end(), rng);
    m.triangles.insert(m.triangles.end(), fan_triangles.begin(), fan_triangles.end());
    const int soup = int(m.vertices.size());
    // Clusters of 8 vertices, 0.1 apart, with 24 triangles each over their own cluster: small
    // triangles whose edges are shared by 1, 2 or more of them, in either direction.
    for (int i = 0; i < 4000; ++i)
        m.vertices.push_back({6 + 0.1 * (i / 8) + 0.05 * u(rng), 0.05 * u(rng), i % 3 == 0 ? (i % 2 ? 0.0 : -0.0) : 0.05 * u(rng)});
    std::uniform_int_distribution<int> pick(0, 7);
    for (int i = 0; i < 12000; ++i) {
        const int cluster = soup + 8 * (i / 24);
        m.triangles.push_back({cluster + pick(rng), cluster + pick(rng), cluster + pick(rng)});  // some repeat a vertex
    }
    m.triangles.push_back({fan, fan + 1, fan + 1});
    m.name = "every-case";
    return m;
}

template <typename V>
bool same_bytes(const V& a, const V& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
}

template <typename T>
void expect_same_buffers(const MeshBuffers<T>& a, const MeshBuffers<T>& b) {
    EXPECT_TRUE(same_bytes(a.vertices, b.vertices));
    EXPECT_TRUE(same_bytes(a.face_normals, b.face_normals));
    EXPECT_TRUE(same_bytes(a.edge_normals, b.edge_normals));
    EXPECT_TRUE(same_bytes(a.vertex_normals, b.vertex_normals));
    EXPECT_TRUE(same_bytes(a.triangles, b.triangles));
    EXPECT_TRUE(same_bytes(a.packed, b.packed));
}

TEST(PreparedMesh, IsTheSameBytesAtEveryThreadCount) {
    const TriangleMesh mesh = every_case_mesh();
    MeshPreparationOptions one;
    one.threads = 1;
    const PreparedMesh a = prepare_mesh(mesh, one);
    ASSERT_GT(a.report().boundary_edges, 0);
    ASSERT_GT(a.report().nonmanifold_edges, 0);
    ASSERT_GT(a.report().inconsistent_edges, 0);
    ASSERT_GT(a.report().degenerate_triangles, 0);
    for (int threads : {2, 3, 7}) {
        SCOPED_TRACE("threads " + std::to_string(threads));
        MeshPreparationOptions o;
        o.threads = threads;
        const PreparedMesh b = prepare_mesh(mesh, o);
        EXPECT_TRUE(same_bytes(a.vertices(), b.vertices()));
        EXPECT_TRUE(same_bytes(a.triangles(), b.triangles()));
        EXPECT_TRUE(same_bytes(a.face_normals(), b.face_normals()));
        EXPECT_TRUE(same_bytes(a.edge_normals(), b.edge_normals()));
        EXPECT_TRUE(same_bytes(a.vertex_normals(), b.vertex_normals()));
        EXPECT_TRUE(same_bytes(a.source_triangle(), b.source_triangle()));
        EXPECT_TRUE(same_bytes(a.shell_of(), b.shell_of()));
        EXPECT_EQ(a.intersecting_triangles(), b.intersecting_triangles());
        expect_same_buffers(a.buffers<float>(), b.buffers<float>());
        expect_same_buffers(a.buffers<double>(), b.buffers<double>());
        const FloatSearchBound x = a.search_bound(), y = b.search_bound();
        EXPECT_EQ(std::memcmp(&x.rho, &y.rho, sizeof(double)), 0);
        EXPECT_EQ(std::memcmp(&x.rho_double, &y.rho_double, sizeof(double)), 0);
        EXPECT_EQ(x.two_l, y.two_l);
        EXPECT_EQ(x.coordinate, y.coordinate);
        EXPECT_EQ(a.report().components, b.report().components);
        EXPECT_EQ(a.report().boundary_edges, b.report().boundary_edges);
        EXPECT_EQ(a.report().nonmanifold_edges, b.report().nonmanifold_edges);
        EXPECT_EQ(a.report().inconsistent_edges, b.report().inconsistent_edges);
        EXPECT_EQ(std::memcmp(&a.report().signed_volume, &b.report().signed_volume, sizeof(double)), 0);
    }
}

/// The edge pseudonormals against an independent adjacency: a std::map from (smaller, larger)
/// vertex id to the edge's uses in triangle order, each use's face normal times pi summed in
/// that order and normalised (a lone face keeps its own normal), bit for bit.
TEST(PreparedMesh, EdgeNormalsSumTheirFacesInTriangleOrder) {
    const PreparedMesh m = prepare_mesh(every_case_mesh());
    std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> uses;  // edge -> (triangle, local edge)
    for (size_t i = 0; i < m.triangles().size(); ++i)
        for (int e = 0; e < 3; ++e) {
            const int a = m.triangles()[i][e], b = m.triangles()[i][(e + 1) % 3];
            uses[{std::min(a, b), std::max(a, b)}].push_back({int(i), e});
        }
    constexpr double kPi = 3.14159265358979323846;
    size_t checked = 0, shared_by_three = 0;
    for (const auto& [edge, list] : uses) {
        Vec3d sum(0.0);
        for (const auto& [t, e] : list) sum += m.face_normals()[size_t(t)] * kPi;
        const Vec3d n = normalize_or_zero(sum);
        shared_by_three += list.size() > 2;
        for (const auto& [t, e] : list) {
            const Vec3d want = length_squared(n) > 0 ? n : m.face_normals()[size_t(t)];
            const Vec3d got = m.edge_normals()[3 * size_t(t) + size_t(e)];
            ASSERT_EQ(std::memcmp(&got, &want, sizeof(Vec3d)), 0) << "triangle " << t << " edge " << e;
            ++checked;
        }
    }
    EXPECT_EQ(checked, 3 * m.triangles().size());
    EXPECT_GT(shared_by_three, 0u);
}

}  // namespace
}  // namespace sdf
