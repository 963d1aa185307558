// The LBVH of the GPU build, emulated on the host (core/bvh/lbvh.h): a valid tree (every
// triangle in exactly one leaf, boxes around their children and triangles, depth bounded),
// queries equal to the double loop over all triangles bit for bit, winding moments equal
// to the direct computation (core/winding/winding_bvh.h) on the same tree within rounding,
// and the fast winding number within its error bound of the SAH tree's.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <random>
#include <utility>

#include "core/bvh/lbvh.h"
#include "core/sampling/adversarial_cases.h"
#include "core/winding/winding_bvh.h"
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

/// Every invariant of the flat layout, walked from the root.
void check_tree(const PreparedMesh& mesh, const TriangleBvh& bvh, int max_leaf, const std::string& what) {
    const int n = int(mesh.triangles().size());
    ASSERT_EQ(int(bvh.triangle_index.size()), n) << what;
    std::vector<int> seen_triangle(size_t(n), 0), seen_slot(size_t(n), 0), node_seen(bvh.nodes.size(), 0);
    for (int32_t t : bvh.triangle_index) ++seen_triangle[size_t(t)];
    for (int t = 0; t < n; ++t) ASSERT_EQ(seen_triangle[size_t(t)], 1) << what << ": triangle " << t;
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
                ASSERT_GE(node.count[c], 1) << what;
                ASSERT_LE(node.count[c], max_leaf) << what;
                for (int s = node.ref[c]; s < node.ref[c] + node.count[c]; ++s) {
                    ++seen_slot[size_t(s)];
                    const Int3 t = mesh.triangles()[size_t(bvh.triangle_index[size_t(s)])];
                    for (int k = 0; k < 3; ++k) ASSERT_TRUE(contains(node, c, mesh.vertices()[size_t(t[k])])) << what;
                    ASSERT_EQ(0, std::memcmp(&bvh.packed_double[size_t(s)], &mesh.buffers<double>().packed[size_t(bvh.triangle_index[size_t(s)])],
                                             sizeof(PackedTriangle<double>))) << what;
                }
                continue;
            }
            ASSERT_GT(node.ref[c], 0) << what;
            if (c == 0) {  // pre-order: a left child right after its parent
                ASSERT_EQ(node.ref[c], it.node + 1) << what;
            }
            ASSERT_LT(node.ref[c], int(bvh.nodes.size())) << what;
            const BvhNode& child = bvh.nodes[size_t(node.ref[c])];
            for (int cc = 0; cc < 2; ++cc) ASSERT_TRUE(box_inside(child, cc, node, c)) << what;
            stack.push_back({node.ref[c], it.depth + 1});
        }
    }
    for (int s = 0; s < n; ++s) ASSERT_EQ(seen_slot[size_t(s)], 1) << what << ": slot " << s;
    for (size_t k = 0; k < node_seen.size(); ++k) ASSERT_EQ(node_seen[k], 1) << what << ": node " << k << " unreachable";
    EXPECT_EQ(deepest, bvh.stats.depth) << what;
    EXPECT_LE(deepest, kBvhMaxDepth) << what;
}

/// The double loop over all triangles with the one tie rule (wins_tie): the truth.
std::pair<int32_t, double> loop_winner(const PreparedMesh& mesh, const Vec3d& p) {
    const auto& packed = mesh.buffers<double>().packed;
    double best = std::numeric_limits<double>::infinity();
    int32_t winner = -1;
    for (size_t t = 0; t < packed.size(); ++t) {
        const double q = squared_distance(packed[t], p);
        if (q < best || (q == best && wins_tie(int32_t(t), winner))) best = q, winner = int32_t(t);
    }
    return {winner, best};
}

/// The double query through `bvh` equals the loop over all triangles, triangle and distance
/// bit for bit with the one tie rule (wins_tie), whatever the tree: the double view's pruning
/// margin (search_certificate.h, PruneMargin) covers the rounding of squared_distance().
void expect_queries_match_loop(const PreparedMesh& mesh, const TriangleBvh& bvh, const std::vector<Vec3d>& pts) {
    const BvhView<double> view = bvh.view<double>();
    ASSERT_TRUE(bvh.float_bound.has_value()) << mesh.name();
    ASSERT_TRUE(std::isfinite(view.margin.rho) && view.margin.rho > 0) << mesh.name() << ": no margin, or the brute force";
    BvhView<double> unwidened = view;  // the old 8-ulp slack alone, for the printed count
    unwidened.margin = {};
    int off_without_margin = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        const Vec3d& p = pts[i];
        const auto [winner, best] = loop_winner(mesh, p);
        const BvhHit<double> hit = closest_triangle_bvh(view, p);
        ASSERT_GE(hit.slot, 0) << mesh.name();
        ASSERT_EQ(bvh.triangle_index[size_t(hit.slot)], winner) << mesh.name() << " point " << i << " q " << hit.distance_squared << " loop " << best << " p " << p.x << " " << p.y << " " << p.z;
        ASSERT_EQ(hit.distance_squared, best) << mesh.name() << " point " << i;
        off_without_margin += closest_triangle_bvh(unwidened, p).distance_squared != best;
    }
    if (off_without_margin > 0)
        std::printf("%-20s without the margin the double query is off the loop's minimum at %d of %zu points\n",
                    mesh.name().c_str(), off_without_margin, pts.size());
}

/// The moments of the bottom-up pass against the direct sums over each child's triangles
/// (core/winding/winding_bvh.cpp) on the same tree.
void expect_moments_match(const PreparedMesh& mesh, const LbvhBuild& b, const std::string& what) {
    const WindingBvh direct = build_winding_bvh(mesh, std::make_shared<const TriangleBvh>(b.bvh));
    ASSERT_EQ(direct.moments.size(), b.moments.size());
    const Bounds3& box = mesh.bounds();
    const double scale = std::max({1.0, length(box.extent()), length(box.min), length(box.max)});
    for (size_t i = 0; i < b.moments.size(); ++i)
        for (int c = 0; c < 2; ++c) {
            const WindingMoments<double>& x = b.moments[i].child[c];
            const WindingMoments<double>& y = direct.moments[i].child[c];
            const double tol = 1e-12 * scale;
            ASSERT_NEAR(x.area, y.area, 1e-12 * y.area) << what << " node " << i;
            ASSERT_NEAR(length(x.center - y.center), 0.0, tol) << what << " node " << i;
            ASSERT_NEAR(length(x.normal_sum - y.normal_sum), 0.0, 1e-12 * y.area) << what << " node " << i;
            ASSERT_NEAR(x.radius, y.radius, tol) << what << " node " << i;
            for (int k = 0; k < 9; ++k) ASSERT_NEAR(x.second[k], y.second[k], 1e-11 * y.area * scale) << what << " node " << i;
        }
}

std::vector<Vec3d> points_around(const PreparedMesh& mesh, int count, unsigned seed) {
    std::mt19937_64 rng(seed);
    const Bounds3 b = mesh.bounds();
    const Vec3d lo = b.min - b.extent() * 0.1, e = b.extent() * 1.2;
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Vec3d> pts(static_cast<size_t>(count));
    for (auto& p : pts) p = lo + Vec3d{u(rng) * e.x, u(rng) * e.y, u(rng) * e.z};
    return pts;
}

GpuBvhBuildOptions gpu_options(GpuBvhBuilder builder, int max_leaf = 4) {
    GpuBvhBuildOptions o;
    o.builder = builder;
    o.max_leaf = max_leaf;
    return o;
}

constexpr GpuBvhBuilder kBuilders[] = {GpuBvhBuilder::Lbvh, GpuBvhBuilder::Ploc};

TEST(Lbvh, ValidTreeExactQueriesAndMomentsOnEveryTestMesh) {
    for (const test::NamedMesh& m : test::bvh_test_meshes()) {
        const TriangleBvh sah = build_triangle_bvh(m.mesh);
        std::printf("%-14s sah  %s\n", m.name.c_str(), sah.stats.to_json().dump().c_str());
        const std::vector<Vec3d> points = points_around(m.mesh, m.mesh.triangles().size() > 50000 ? 200 : 1000, 3);
        expect_queries_match_loop(m.mesh, sah, points);  // the SAH tree too: the same minimum
        for (GpuBvhBuilder builder : kBuilders) {
            const std::string what = m.name + " " + gpu_bvh_builder_name(builder);
            const LbvhBuild b = build_lbvh(m.mesh, gpu_options(builder));
            ASSERT_TRUE(b.within_depth) << what;
            check_tree(m.mesh, b.bvh, 4, what);
            expect_queries_match_loop(m.mesh, b.bvh, points);
            expect_moments_match(m.mesh, b, what);
            std::printf("%-14s %s %s\n", m.name.c_str(), gpu_bvh_builder_name(builder), b.bvh.stats.to_json().dump().c_str());
        }
    }
}

TEST(Lbvh, ValidTreeAndExactQueriesOnAdversarialCases) {
    for (const AdversarialCase& c : adversarial_cases(11, 400)) {
        MeshPreparationOptions po;
        po.orient_outward = false;
        const PreparedMesh mesh = prepare_mesh(c.mesh, po);
        if (int(mesh.triangles().size()) <= 4) continue;
        expect_queries_match_loop(mesh, build_triangle_bvh(mesh), c.points);
        for (int leaf : {1, 4})
        for (GpuBvhBuilder builder : kBuilders) {
            const LbvhBuild b = build_lbvh(mesh, gpu_options(builder, leaf));
            ASSERT_TRUE(b.within_depth) << mesh.name();
            check_tree(mesh, b.bvh, leaf, mesh.name());
            expect_queries_match_loop(mesh, b.bvh, c.points);
            expect_moments_match(mesh, b, mesh.name());
        }
    }
}

template <typename V, typename A>
void expect_bytes_equal(const std::vector<V, A>& a, const std::vector<V, A>& b, const std::string& what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(V))) << what << " differ";
}

/// The GPU runs each step's elements in any order (and the bottom-up pass's second arrival
/// is whichever thread comes second): the emulation in shuffled orders gives the same
/// bytes, so the device build, which the GPU test compares with the emulation, does too.
TEST(Lbvh, AnyOrderOfTheElementsGivesTheSameTree) {
    for (const test::NamedMesh& m : test::bvh_test_meshes()) {
        if (m.mesh.triangles().size() > 50000) continue;
        for (GpuBvhBuilder builder : kBuilders) {
            const std::string what = m.name + " " + gpu_bvh_builder_name(builder);
            const LbvhBuild in_order = build_lbvh(m.mesh, gpu_options(builder));
            for (uint64_t seed : {1u, 2u}) {
                GpuBvhBuildOptions o = gpu_options(builder);
                o.emulation_shuffle_seed = seed;
                const LbvhBuild shuffled = build_lbvh(m.mesh, o);
                expect_bytes_equal(shuffled.bvh.nodes, in_order.bvh.nodes, what + " nodes");
                expect_bytes_equal(shuffled.moments, in_order.moments, what + " moments");
                expect_bytes_equal(shuffled.bvh.triangle_index, in_order.bvh.triangle_index, what + " slots");
                EXPECT_EQ(shuffled.bvh.stats.depth, in_order.bvh.stats.depth) << what;
            }
        }
    }
}

/// Equal keys (every centroid the same) are split by their slots: still a valid tree.
TEST(Lbvh, EqualKeysStillGiveAValidTree) {
    TriangleMesh m;
    m.name = "same_centroid";
    const int n = 300;
    for (int i = 0; i < n; ++i) {
        const double a = 0.01 * i;
        const Vec3d e1{std::cos(a), std::sin(a), 0.1 * i / n}, e2{-std::sin(a), std::cos(a), -0.05};
        for (const Vec3d& v : {e1, e2, -(e1 + e2)}) m.vertices.push_back(v);
        m.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
    }
    MeshPreparationOptions po;
    po.orient_outward = false;
    const PreparedMesh mesh = prepare_mesh(m, po);
    for (GpuBvhBuilder builder : kBuilders) {
        const LbvhBuild b = build_lbvh(mesh, gpu_options(builder));
        ASSERT_TRUE(b.within_depth);
        check_tree(mesh, b.bvh, 4, mesh.name());
        expect_queries_match_loop(mesh, b.bvh, points_around(mesh, 500, 9));
    }
}

/// The fast winding number (beta 2, order 2) through the LBVH and through the SAH tree:
/// both within their error bounds of the exact value, so within the sum of the bounds of
/// each other; where both are certain of the side, the sides agree. Where the fast value is
/// within its bound of 1/2 the side may depend on the tree: counted and printed.
TEST(Lbvh, FastWindingNumberAgreesWithTheSahTreeWithinItsBound) {
    for (const test::NamedMesh& m : test::bvh_test_meshes()) {
        const LbvhBuild b = build_lbvh(m.mesh);  // the default builder
        const auto lbvh_tree = std::make_shared<const TriangleBvh>(b.bvh);
        WindingBvh lw;
        lw.bvh = lbvh_tree;
        lw.moments = b.moments;
        const WindingBvh sw = build_winding_bvh(m.mesh);
        const WindingView<double> lv = lw.view<double>(m.mesh), sv = sw.view<double>(m.mesh);
        const WindingAccuracy<double> acc;
        int differ = 0, total = 0;
        for (const Vec3d& p : points_around(m.mesh, m.mesh.triangles().size() > 50000 ? 2000 : 5000, 21)) {
            const WindingEstimate<double> x = fast_winding_number(lv, p, acc), y = fast_winding_number(sv, p, acc);
            ASSERT_LE(std::abs(x.value - y.value), x.error_bound + y.error_bound + 1e-9) << m.name;
            const bool certain = std::abs(x.value - 0.5) > x.error_bound + 1e-9 && std::abs(y.value - 0.5) > y.error_bound + 1e-9;
            if (certain) {
                ASSERT_EQ(x.value > 0.5, y.value > 0.5) << m.name;
            }
            differ += (x.value > 0.5) != (y.value > 0.5);
            ++total;
        }
        std::printf("%-14s winding sides differing between the LBVH and the SAH tree: %d of %d points\n", m.name.c_str(),
                    differ, total);
    }
}

/// The needle fans (bvh_test_meshes.h) 1e7 from the origin and near it: every tree gives the loop.
TEST(Lbvh, NeedleFansFarFromTheOriginGiveTheLoop) {
    for (const Vec3d center : {Vec3d{1e7, -3e6, 5e6}, Vec3d{0.5, 0.25, -0.125}}) {
        const test::NeedleFan fan = test::make_needle_fan(center);
        const PreparedMesh mesh = test::prepare_needle_fan(fan);
        const std::vector<Vec3d>& pts = fan.points;
        expect_queries_match_loop(mesh, build_triangle_bvh(mesh), pts);
        for (int leaf : {1, 4})
            for (GpuBvhBuilder builder : kBuilders) {
                const LbvhBuild b = build_lbvh(mesh, gpu_options(builder, leaf));
                check_tree(mesh, b.bvh, leaf, mesh.name());
                expect_queries_match_loop(mesh, b.bvh, pts);
            }
    }
}

/// A tree without the mesh's bound (made by hand) searches like the brute force: its margin
/// is infinite, also where the radius is 0 (a point on the surface; inf * 0 must not make
/// the radius NaN and skip every box), so the tie at a vertex goes to the smallest index.
TEST(Lbvh, TreeWithoutTheBoundIsTheBruteForceAtSurfacePoints) {
    TriangleMesh m;
    m.name = "fan_without_bound";
    const int spokes = 64;
    m.vertices.push_back({0, 0, 0});
    for (int i = 0; i < spokes; ++i) {
        const double a = 2 * M_PI * i / spokes;
        m.vertices.push_back({std::cos(a), std::sin(a), 0.1 * (i % 3)});
    }
    // The apex last in the triangles with large indices, first in those with small ones:
    // every triangle's Q at the apex is exactly 0.
    for (int i = 0; i < spokes; ++i) m.triangles.push_back({1 + i, 1 + (i + 1) % spokes, 0});
    MeshPreparationOptions po;
    po.orient_outward = false;
    const PreparedMesh mesh = prepare_mesh(m, po);
    for (GpuBvhBuilder builder : kBuilders) {
        LbvhBuild b = build_lbvh(mesh, gpu_options(builder, 1));
        b.bvh.float_bound.reset();
        const BvhView<double> view = b.bvh.view<double>();
        for (const Vec3d& p : {Vec3d{0, 0, 0}, mesh.vertices()[5], mesh.vertices()[40]}) {
            const auto [winner, best] = loop_winner(mesh, p);
            const BvhHit<double> hit = closest_triangle_bvh(view, p);
            ASSERT_GE(hit.slot, 0);
            EXPECT_EQ(hit.distance_squared, best);
            EXPECT_EQ(b.bvh.triangle_index[size_t(hit.slot)], winner) << "point " << p.x << " " << p.y;
        }
    }
}

TEST(Lbvh, RejectsMeshesThatFitOneLeaf) {
    const PreparedMesh mesh = prepare_mesh(make_box());  // 12 triangles
    for (GpuBvhBuilder builder : kBuilders) {
        EXPECT_THROW(build_lbvh(mesh, gpu_options(builder, 12)), std::invalid_argument);
        EXPECT_NO_THROW(build_lbvh(mesh, gpu_options(builder, 11)));
    }
}

}  // namespace
}  // namespace sdf
