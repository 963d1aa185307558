// Point location in the BCC Delaunay tetrahedralisation (bcc_tetrahedron.h): the located
// tetrahedron holds the point, has 2 primary and 2 secondary vertices, is congruent to the
// reference one, and is Delaunay (no lattice point inside its circumsphere).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>

#include "kernels/reconstruction/bcc_tetrahedron.h"
#include "reconstruction_test_util.h"

namespace sdf {
namespace {

Vec3d to_vec(const Int3& c) { return {double(c.x), double(c.y), double(c.z)}; }

/// Barycentric coordinates of u in the tetrahedron with the given vertices (Cramer's rule).
void barycentrics(const Vec3d v[4], const Vec3d& u, double b[4]) {
    const Vec3d e1 = v[1] - v[0], e2 = v[2] - v[0], e3 = v[3] - v[0], d = u - v[0];
    const double det = dot(e1, cross(e2, e3));
    b[1] = dot(d, cross(e2, e3)) / det;
    b[2] = dot(e1, cross(d, e3)) / det;
    b[3] = dot(e1, cross(e2, d)) / det;
    b[0] = 1 - b[1] - b[2] - b[3];
}

/// Circumcentre: solves 2 (v_k - v_0) . x = |v_k|^2 - |v_0|^2 by Cramer's rule.
Vec3d circumcentre(const Vec3d v[4]) {
    const Vec3d a = (v[1] - v[0]) * 2.0, b = (v[2] - v[0]) * 2.0, c = (v[3] - v[0]) * 2.0;
    const Vec3d rhs(length_squared(v[1]) - length_squared(v[0]), length_squared(v[2]) - length_squared(v[0]),
                    length_squared(v[3]) - length_squared(v[0]));
    // Rows a, b, c; the solution is (rhs . (b x c), rhs . (c x a), rhs . (a x b)) / det
    const double det = dot(a, cross(b, c));
    const Vec3d bc = cross(b, c), ca = cross(c, a), ab = cross(a, b);
    return Vec3d(rhs.x * bc.x + rhs.y * ca.x + rhs.z * ab.x, rhs.x * bc.y + rhs.y * ca.y + rhs.z * ab.y,
                 rhs.x * bc.z + rhs.y * ca.z + rhs.z * ab.z) / det;
}

TEST(BccTetrahedron, LocatedTetrahedronHoldsThePointAndIsDelaunay) {
    const Lattice l = test::make_lattice(LatticeType::BCC, {6, 7, 5}, 1.0, {0, 0, 0});
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u01(0, 1);
    std::set<std::array<int, 12>> seen;
    for (int trial = 0; trial < 20000; ++trial) {
        const Vec3d u(1 + u01(rng) * (2 * 6 - 4), 1 + u01(rng) * (2 * 7 - 4), 1 + u01(rng) * (2 * 5 - 4));
        const BccTetrahedron tet = bcc_tetrahedron_at(l, u);
        Vec3d v[4];
        int primary = 0;
        for (int k = 0; k < 4; ++k) {
            const Int3 c = tet.vertex(k);
            ASSERT_GE(l.index_of_coords(c), 0) << "vertex outside the lattice";
            primary += (c.x & 1) == 0;
            v[k] = to_vec(c);
        }
        EXPECT_EQ(primary, 2);
        double b[4];
        barycentrics(v, u, b);
        for (double x : b) EXPECT_GE(x, -1e-12);
        // The reference map sends the vertices to V0..V3 and agrees with the barycentrics
        double lam[4];
        bcc_reference_barycentrics(tet.to_reference(u), lam);
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(lam[k], b[k], 1e-12);
        // Delaunay: no lattice point strictly inside the circumsphere
        const Vec3d centre = circumcentre(v);
        const double r2 = length_squared(v[2] - centre);
        for (int k = 0; k < 4; ++k) EXPECT_NEAR(length_squared(v[k] - centre), r2, 1e-12);
        for (int dz = -3; dz <= 3; ++dz)
            for (int dy = -3; dy <= 3; ++dy)
                for (int dx = -3; dx <= 3; ++dx) {
                    const Int3 c{int(std::lround(centre.x)) + dx, int(std::lround(centre.y)) + dy,
                                 int(std::lround(centre.z)) + dz};
                    if ((c.x & 1) != (c.y & 1) || (c.y & 1) != (c.z & 1)) continue;
                    EXPECT_GE(length_squared(to_vec(c) - centre), r2 - 1e-12);
                }
        std::array<int, 12> key{};
        std::multiset<std::array<int, 3>> sorted;
        for (int k = 0; k < 4; ++k) sorted.insert({int(v[k].x), int(v[k].y), int(v[k].z)});
        int n = 0;
        for (const auto& s : sorted) for (int x : s) key[size_t(n++)] = x;
        seen.insert(key);
    }
    EXPECT_GT(seen.size(), 500u);  // many distinct tetrahedra were visited
}

std::set<std::array<int, 3>> vertex_set(const BccTetrahedron& t) {
    std::set<std::array<int, 3>> s;
    for (int v = 0; v < 4; ++v) s.insert({t.vertex(v).x, t.vertex(v).y, t.vertex(v).z});
    return s;
}

TEST(BccTetrahedron, TetrahedraTileSpace) {
    // The tiling has period 2 (lattice units) on every axis and volume 8 per period, so with
    // tetrahedra of volume 2/3 a box of side 4 holds exactly 8 * 12 = 96 tetrahedron
    // centroids. Every tetrahedron the grid meets must also be the one located at its own
    // centroid.
    const Lattice l = test::make_lattice(LatticeType::BCC, {7, 7, 7}, 1.0, {0, 0, 0});
    std::set<std::array<int, 3>> centroids;  // 4 x centroid, an integer vector
    const int n = 60;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const Vec3d u(2 + 8 * (i + 0.5) / n, 2 + 8 * (j + 0.5) / n, 2 + 8 * (k + 0.5) / n);
                const BccTetrahedron t = bcc_tetrahedron_at(l, u);
                Int3 sum{0, 0, 0};
                for (int v = 0; v < 4; ++v)
                    for (int a = 0; a < 3; ++a) sum[a] += t.vertex(v)[a];
                const BccTetrahedron again = bcc_tetrahedron_at(l, Vec3d(sum.x, sum.y, sum.z) * 0.25);
                ASSERT_EQ(vertex_set(again), vertex_set(t));  // same tetrahedron, maybe relabelled
                bool inside = true;
                for (int a = 0; a < 3; ++a) inside &= sum[a] >= 4 * 4 && sum[a] < 4 * 8;
                if (inside) centroids.insert({sum.x, sum.y, sum.z});
            }
    EXPECT_EQ(centroids.size(), 96u);
    const Vec3d v1(2, 0, 0), v2(1, 1, -1), v3(1, 1, 1);
    EXPECT_NEAR(std::abs(dot(v1, cross(v2, v3))) / 6.0, 2.0 / 3.0, 1e-15);
}

TEST(BccTetrahedron, PointsAtTheDomainCornersAndCentresAreLocatedInside) {
    const Lattice l = test::make_lattice(LatticeType::BCC, {3, 3, 3}, 1.0, {0, 0, 0});
    for (const Vec3d& u : {Vec3d(1, 1, 1), Vec3d(3, 3, 3), Vec3d(1, 3, 1), Vec3d(2, 2, 2), Vec3d(3, 1, 2.5)}) {
        const BccTetrahedron tet = bcc_tetrahedron_at(l, u);
        for (int k = 0; k < 4; ++k) EXPECT_GE(l.index_of_coords(tet.vertex(k)), 0) << u.x << " " << u.y << " " << u.z;
    }
}

}  // namespace
}  // namespace sdf
