// The BVH's own invariants: every triangle in exactly one leaf, child boxes inside their
// parent's box, leaf boxes around their triangles, bounded depth and leaf size; and the
// query against a plain loop over all triangles on meshes that stress the builder.
#include <gtest/gtest.h>

#include <random>

#include "core/bvh/triangle_bvh.h"
#include "kernels/bvh/closest_triangle_bvh.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"

namespace sdf {
namespace {

bool box_inside(const BvhNode& inner, int ic, const BvhNode& outer, int oc) {
    return inner.min_x[ic] >= outer.min_x[oc] && inner.max_x[ic] <= outer.max_x[oc] && inner.min_y[ic] >= outer.min_y[oc] &&
           inner.max_y[ic] <= outer.max_y[oc] && inner.min_z[ic] >= outer.min_z[oc] && inner.max_z[ic] <= outer.max_z[oc];
}

bool contains(const BvhNode& n, int c, const Vec3d& v) {
    return v.x >= n.min_x[c] && v.x <= n.max_x[c] && v.y >= n.min_y[c] && v.y <= n.max_y[c] && v.z >= n.min_z[c] &&
           v.z <= n.max_z[c];
}

/// Walks the tree from the root and checks every invariant; returns the leaf count.
void check_invariants(const PreparedMesh& mesh, const TriangleBvh& bvh, const BvhBuildOptions& o, const std::string& what) {
    const int n = int(mesh.triangles().size());
    ASSERT_EQ(int(bvh.triangle_index.size()), n) << what;
    std::vector<int> seen_slot(size_t(n), 0), seen_triangle(size_t(n), 0);
    for (int32_t t : bvh.triangle_index) ++seen_triangle[size_t(t)];
    for (int t = 0; t < n; ++t) ASSERT_EQ(seen_triangle[size_t(t)], 1) << what << ": triangle " << t;
    std::vector<int> node_seen(bvh.nodes.size(), 0);
    struct Item { int node, depth; };
    std::vector<Item> stack{{0, 1}};
    int deepest = 0;
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        ASSERT_EQ(node_seen[size_t(it.node)]++, 0) << what << ": node reached twice";
        deepest = std::max(deepest, it.depth);
        const BvhNode& node = bvh.nodes[size_t(it.node)];
        for (int c = 0; c < 2; ++c) {
            if (bvh_child_is_leaf(node, c)) {
                ASSERT_LE(node.count[c], o.max_leaf_size) << what;
                for (int s = node.ref[c]; s < node.ref[c] + node.count[c]; ++s) {
                    ++seen_slot[size_t(s)];
                    const Int3 t = mesh.triangles()[size_t(bvh.triangle_index[size_t(s)])];
                    for (int k = 0; k < 3; ++k) {
                        ASSERT_TRUE(contains(node, c, mesh.vertices()[size_t(t[k])])) << what;
                    }
                }
                continue;
            }
            const BvhNode& child = bvh.nodes[size_t(node.ref[c])];
            for (int cc = 0; cc < 2; ++cc) {
                if (child.count[cc] > 0 || child.ref[cc] > 0) {
                    ASSERT_TRUE(box_inside(child, cc, node, c)) << what;
                }
            }
            stack.push_back({node.ref[c], it.depth + 1});
        }
    }
    for (int s = 0; s < n; ++s) ASSERT_EQ(seen_slot[size_t(s)], 1) << what << ": slot " << s << " not in exactly one leaf";
    for (size_t k = 0; k < node_seen.size(); ++k) ASSERT_EQ(node_seen[k], 1) << what << ": node " << k << " unreachable";
    EXPECT_EQ(deepest, bvh.stats.depth) << what;
    EXPECT_LE(deepest, kBvhMaxDepth) << what;
}

/// Random triangle soup (open, overlapping): stresses the builder and the pruning.
TriangleMesh random_soup(int n, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1), s(0.001, 0.2);
    TriangleMesh m;
    m.name = "soup";
    for (int i = 0; i < n; ++i) {
        const Vec3d c{u(rng), u(rng), u(rng)};
        const double r = s(rng);
        for (int k = 0; k < 3; ++k) m.vertices.push_back(c + Vec3d{u(rng), u(rng), u(rng)} * r);
        m.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    return m;
}

/// Many triangles with the same centroid (a fan of rotated copies): SAH cannot split them.
TriangleMesh same_centroid_stack(int n) {
    TriangleMesh m;
    m.name = "same_centroid";
    for (int i = 0; i < n; ++i) {
        const double a = 0.01 * i;
        const Vec3d e1{std::cos(a), std::sin(a), 0.1 * i / n}, e2{-std::sin(a), std::cos(a), -0.05};
        const Vec3d v0 = e1, v1 = e2, v2 = -(e1 + e2);  // centroid 0
        for (const Vec3d& v : {v0, v1, v2}) m.vertices.push_back(v);
        m.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    return m;
}

TEST(TriangleBvh, InvariantsOnEveryTestMesh) {
    for (const test::NamedMesh& m : test::bvh_test_meshes()) {
        for (int leaf : {1, 4, 8}) {
            BvhBuildOptions o;
            o.max_leaf_size = leaf;
            const TriangleBvh bvh = build_triangle_bvh(m.mesh, o);
            check_invariants(m.mesh, bvh, o, m.name + " leaf " + std::to_string(leaf));
            if (leaf == 4)
                std::printf("%-14s %7zu triangles: %s\n", m.name.c_str(), m.mesh.triangles().size(), bvh.stats.to_json().dump().c_str());
        }
    }
}

/// The query against a loop over all triangles with the same squared_distance().
void expect_query_matches_loop(const PreparedMesh& mesh, const TriangleBvh& bvh, const std::vector<Vec3d>& pts) {
    const BvhView<double> view = bvh.view<double>();
    for (const Vec3d& p : pts) {
        double best = std::numeric_limits<double>::infinity();
        for (int s = 0; s < view.num_triangles; ++s) best = std::min(best, squared_distance(view.packed[s], p));
        const BvhHit<double> hit = closest_triangle_bvh(view, p);
        ASSERT_GE(hit.slot, 0) << mesh.name();
        ASSERT_EQ(hit.distance_squared, best) << mesh.name();  // same arithmetic: the very same minimum
        // Seeding with any triangle changes nothing but the work.
        const BvhHit<double> seeded = closest_triangle_bvh(view, p, seed_hit(view, int32_t(view.num_triangles / 2), p));
        ASSERT_EQ(seeded.distance_squared, best) << mesh.name();
    }
}

TEST(TriangleBvh, QueryFindsTheLoopMinimumOnStressMeshes) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    std::vector<Vec3d> pts(3000);
    for (auto& p : pts) p = {u(rng), u(rng), u(rng)};
    for (const TriangleMesh& raw : {random_soup(3000, 1), same_centroid_stack(500), test::make_sliver_sphere(2)}) {
        MeshPreparationOptions po;
        po.orient_outward = false;
        const PreparedMesh mesh = prepare_mesh(raw, po);
        for (int leaf : {1, 4}) {
            BvhBuildOptions o;
            o.max_leaf_size = leaf;
            const TriangleBvh bvh = build_triangle_bvh(mesh, o);
            check_invariants(mesh, bvh, o, mesh.name());
            expect_query_matches_loop(mesh, bvh, pts);
        }
    }
}

TEST(TriangleBvh, OneTriangleMeshHasARootWithAnEmptyChild) {
    TriangleMesh m;
    m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    m.triangles = {{0, 1, 2}};
    MeshPreparationOptions po;
    po.orient_outward = false;
    const PreparedMesh mesh = prepare_mesh(m, po);
    const TriangleBvh bvh = build_triangle_bvh(mesh);
    ASSERT_EQ(bvh.nodes.size(), 1u);
    EXPECT_EQ(bvh.nodes[0].count[0], 1);
    EXPECT_EQ(bvh.nodes[0].count[1], 0);
    const BvhHit<float> hit = closest_triangle_bvh(bvh.view<float>(), Vec3f{0.2f, 0.2f, 2.0f});
    EXPECT_EQ(hit.slot, 0);
    EXPECT_FLOAT_EQ(hit.distance_squared, 4.0f);
}

TEST(TriangleBvh, BoxesRoundOutward) {
    for (double x : {0.1, -0.1, 1.0 / 3.0, -1e-30, 123456.789}) {
        EXPECT_LE(double(round_down_to_float(x)), x);
        EXPECT_GE(double(round_up_to_float(x)), x);
    }
}

TEST(TriangleBvh, RejectsBadOptions) {
    const PreparedMesh mesh = prepare_mesh(make_box());
    BvhBuildOptions o;
    o.max_leaf_size = 0;
    EXPECT_THROW(build_triangle_bvh(mesh, o), std::invalid_argument);
}

}  // namespace
}  // namespace sdf
