// The certified winding sign (kernels/winding/certified_winding.h) against a brute-force exact
// winding number in long double (an independent evaluation: other precision, no tree, no
// bound): on meshes with holes, overlapping shells and self-intersections, at random points
// and at points placed within 1e-15 .. 1e-3 of the w = 1/2 surface that spans each hole, the
// sign from the host SAH tree, from the GPU build's trees (PLOC and LBVH, their host emulation
// core/bvh/lbvh.h with the device's moments) and the exact side agree at every point; ties
// (outside) only where the exact w is within 1e-12 of 1/2 or the point is on the surface. Also:
// the certified bound holds (|w_certified - w_exact| <= bound, fast, refined and direct),
// and the counters add up.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "core/bvh/lbvh.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/winding/winding_sign.h"
#include "kernels/winding/certified_winding.h"
#include "kernels/winding/certified_winding_packet.h"
#include "tests/core/winding/exact_winding_long.h"
#include "tests/core/winding/mesh_parts.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"

namespace sdf {
namespace {

double distance_to_mesh(const PreparedMesh& m, const Vec3d& p) {
    double best = 1e300;
    for (const Int3& t : m.triangles()) {
        const Vec3d a = m.vertices()[size_t(t.x)], b = m.vertices()[size_t(t.y)], c = m.vertices()[size_t(t.z)];
        // The distance to the triangle's edges, and to its plane where p projects inside it.
        const Vec3d n = cross(b - a, c - a);
        const double ln = length(n);
        auto segment = [&](const Vec3d& x, const Vec3d& y) {
            const double l2 = length_squared(y - x);
            const double t = l2 > 0 ? std::clamp(dot(p - x, y - x) / l2, 0.0, 1.0) : 0.0;
            return length(p - (x + (y - x) * t));
        };
        double d = std::min({segment(a, b), segment(b, c), segment(c, a)});
        if (ln > 0) {
            const double h = std::abs(dot(p - a, n)) / ln;
            const Vec3d q = p - n * (dot(p - a, n) / (ln * ln));
            const bool in = dot(cross(b - a, q - a), n) >= 0 && dot(cross(c - b, q - b), n) >= 0 && dot(cross(a - c, q - c), n) >= 0;
            if (in) d = std::min(d, h);
        }
        best = std::min(best, d);
    }
    return best;
}

/// An icosphere with the triangles above `z_cut` removed: a hole whose spanning surface
/// (w = 1/2) the points below cross.
TriangleMesh holed_sphere(int subdivisions, double z_cut, Vec3d center, const char* name) {
    TriangleMesh m = make_icosphere(subdivisions, 1.0, center);
    std::vector<Int3> kept;
    for (const Int3& t : m.triangles)
        if (m.vertices[size_t(t.x)].z + m.vertices[size_t(t.y)].z + m.vertices[size_t(t.z)].z < 3 * (center.z + z_cut))
            kept.push_back(t);
    m.triangles = kept;
    m.name = name;
    return m;
}

struct Case {
    PreparedMesh mesh;
    std::vector<Vec3d> holes;  ///< a point inside each hole's rim, on the vertical through it
};

std::vector<Case> cases() {
    std::vector<Case> c;
    c.push_back({prepare_mesh(holed_sphere(3, 0.6, {0, 0, 0}, "bowl")), {{0.05, 0.02, 0.3}}});
    c.push_back({prepare_mesh(holed_sphere(2, 0.85, {0, 0, 0}, "small hole")), {{0.01, -0.02, 0.5}}});
    // Overlapping shells: two spheres through each other, one of them open.
    c.push_back({prepare_mesh(test::concatenated({make_icosphere(3, 1.0), holed_sphere(2, 0.5, {0.8, 0.1, 0.0}, "")},
                                           "overlapping shells")),
                 {{0.83, 0.12, 0.2}}});
    // Self-intersecting: a torus thicker than its hole.
    TriangleMesh thick = make_torus(0.5, 0.7, 32, 16);
    thick.name = "thick torus";
    c.push_back({prepare_mesh(thick), {}});
    const std::string bunny = test::find_data_file("bunny-open.obj");
    if (!bunny.empty()) c.push_back({prepare_mesh(load_mesh_file(bunny)), {}});
    return c;
}

/// Points around the mesh, and for each hole points at signed offsets 1e-15 .. 1e-3 from
/// where w crosses 1/2 on the vertical line through the hole (found by bisection on the long
/// double sum).
std::vector<Vec3d> test_points(const Case& c, int random_count, unsigned seed) {
    std::vector<Vec3d> pts;
    const Bounds3 b = c.mesh.bounds();
    const Vec3d pad = b.extent() * 0.15;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < random_count; ++i) {
        const Vec3d lo = b.min - pad, hi = b.max + pad;
        pts.push_back({lo.x + (hi.x - lo.x) * u(rng), lo.y + (hi.y - lo.y) * u(rng), lo.z + (hi.z - lo.z) * u(rng)});
    }
    for (const Vec3d& h : c.holes) {
        double lo = h.z - 0.5, hi = h.z + 1.0;  // w > 1/2 below (inside), < 1/2 above
        auto w_at = [&](double z) { return exact_winding_long(c.mesh, {h.x, h.y, z}); };
        if (!(w_at(lo) > 0.5L && w_at(hi) < 0.5L)) {
            ADD_FAILURE() << c.mesh.name() << ": the hole's vertical does not cross w = 1/2";
            continue;
        }
        for (int k = 0; k < 80; ++k) {
            const double mid = 0.5 * (lo + hi);
            (w_at(mid) > 0.5L ? lo : hi) = mid;
        }
        for (double off : {0.0, 1e-15, 1e-14, 1e-13, 1e-12, 1e-11, 1e-10, 1e-9, 1e-7, 1e-5, 1e-3})
            for (double s : {-1.0, 1.0}) pts.push_back({h.x, h.y, lo + s * off});
        // A small disc of points across the spanning surface.
        for (int i = 0; i < 60; ++i) {
            const double r = 0.08 * u(rng), a = 6.283185307179586 * u(rng), dz = (u(rng) - 0.5) * 2e-6;
            pts.push_back({h.x + r * std::cos(a), h.y + r * std::sin(a), lo + dz});
        }
    }
    // Points on the surface itself (ties: w is undefined there) and just off it.
    for (size_t t = 0; t < c.mesh.triangles().size(); t += std::max<size_t>(1, c.mesh.triangles().size() / 40)) {
        const Int3 tri = c.mesh.triangles()[t];
        const Vec3d a = c.mesh.vertices()[size_t(tri.x)], bb = c.mesh.vertices()[size_t(tri.y)], cc = c.mesh.vertices()[size_t(tri.z)];
        pts.push_back((a + bb + cc) / 3.0);
        pts.push_back(a);
        pts.push_back((a + bb) * 0.5);
    }
    return pts;
}

WindingSign lbvh_sign(const PreparedMesh& mesh, GpuBvhBuilder builder) {
    GpuBvhBuildOptions o;
    o.builder = builder;
    LbvhBuild b = build_lbvh(mesh, o);
    EXPECT_TRUE(b.within_depth);
    WindingBvh w;
    w.bvh = std::make_shared<const TriangleBvh>(std::move(b.bvh));
    w.moments = std::move(b.moments);
    return WindingSign(mesh, std::move(w));
}

TEST(CertifiedWindingSign, EveryTreeGivesTheExactSide) {
    for (const Case& c : cases()) {
        const PreparedMesh& mesh = c.mesh;
        const WindingSign sah(mesh);
        const WindingSign ploc = lbvh_sign(mesh, GpuBvhBuilder::Ploc), lbvh = lbvh_sign(mesh, GpuBvhBuilder::Lbvh);
        const std::vector<Vec3d> pts = test_points(c, mesh.triangles().size() > 20000 ? 400 : 1500, 5);
        int ties = 0, near_half = 0, fast_wrong = 0;
        WindingSignCounts n;
        for (size_t i = 0; i < pts.size(); ++i) {
            const Vec3d& p = pts[i];
            const WindingSide s = sah.side(p), sp = ploc.side(p), sl = lbvh.side(p);
            n.add(s.stage);
            ASSERT_EQ(s.inside, sp.inside) << mesh.name() << " point " << i;
            ASSERT_EQ(s.inside, sl.inside) << mesh.name() << " point " << i;
            const long double w = exact_winding_long(mesh, p);
            const bool exact_inside = w > 0.5L;
            if (std::abs(double(w - 0.5L)) < 1e-12) ++near_half;
            if (s.stage == WindingStage::Tie) {
                ++ties;
                // Ties only on the surface or where w is 1/2 to within the double sum's error.
                ASSERT_TRUE(std::abs(double(w - 0.5L)) < 1e-12 || distance_to_mesh(mesh, p) < 1e-9)
                    << mesh.name() << " point " << i << " w = " << double(w);
                ASSERT_EQ(sp.stage, WindingStage::Tie) << mesh.name() << " point " << i;
                ASSERT_FALSE(s.inside);
                continue;
            }
            ASSERT_EQ(s.inside, exact_inside) << mesh.name() << " point " << i << " w = " << double(w) << " stage "
                                              << int(s.stage);
            fast_wrong += (fast_winding_number(sah.view(), p, WindingAccuracy<double>{}).value > 0.5) != exact_inside;
        }
        EXPECT_EQ(n.points(), int64_t(pts.size()));
        EXPECT_EQ(n.ties, ties);
        std::printf("%-20s %zu points: fast %lld, refined %lld, direct %lld, ties %d (w within 1e-12 of 1/2: %d); "
                    "the uncertified fast sign was wrong at %d\n",
                    mesh.name().c_str(), pts.size(), (long long)n.fast, (long long)n.refined, (long long)n.direct, ties,
                    near_half, fast_wrong);
        EXPECT_GT(n.refined + n.direct, 0) << mesh.name();  // the ladder is exercised
    }
}

/// |w - w_exact| <= bound for the certified fast evaluation (several betas and orders) and the
/// direct sum.
TEST(CertifiedWindingSign, TheBoundHolds) {
    for (const Case& c : cases()) {
        const WindingSign sah(c.mesh);
        for (const Vec3d& p : test_points(c, 300, 11)) {
            if (distance_to_mesh(c.mesh, p) < 1e-9) continue;
            const long double w = exact_winding_long(c.mesh, p);
            for (int order : {1, 2})
                for (double beta : {2.0, 4.0, 16.0}) {
                    const WindingEstimate<double> e = certified_winding_number(sah.view(), p, {beta, order});
                    ASSERT_LE(std::abs(double(e.value - w)), e.error_bound) << c.mesh.name() << " beta " << beta;
                }
            const WindingEstimate<double> d = certified_winding_direct(sah.view(), p);
            ASSERT_LE(std::abs(double(d.value - w)), d.error_bound) << c.mesh.name();
            EXPECT_LT(d.error_bound, 1e-9) << c.mesh.name();  // off the surface the direct sum is tight
        }
    }
}

/// The CPU BVH sampler's packets (certified_winding_packet.h): every lane's side and stage,
/// and its first estimate bit for bit, are the point's own.
TEST(CertifiedWindingSign, PacketLanesEqualThePointEvaluation) {
    constexpr int K = 16;
    for (const Case& c : cases()) {
        const WindingSign sah(c.mesh);
        const std::vector<Vec3d> pts = test_points(c, 600, 17);
        for (size_t first = 0; first < pts.size(); first += K) {
            const int count = int(std::min<size_t>(K, pts.size() - first));
            Vec3d p[K];
            int64_t lanes[K];
            for (int k = 0; k < K; ++k) {
                p[k] = pts[first + size_t(k < count ? k : 0)];
                lanes[k] = k < count;
            }
            WindingSide side[K];
            certified_winding_sides_packet<K>(sah.view(), p, count, sah.options().accuracy, sah.options().certification, side);
            double value[K], bound[K];
            certified_winding_numbers_packet<K>(sah.view(), p, lanes, sah.options().accuracy, value, bound);
            for (int k = 0; k < count; ++k) {
                const WindingSide s = certified_winding_side(sah.view(), p[k], sah.options().accuracy, sah.options().certification);
                ASSERT_EQ(side[k].inside, s.inside) << c.mesh.name() << " point " << first + size_t(k);
                ASSERT_EQ(side[k].stage, s.stage) << c.mesh.name() << " point " << first + size_t(k);
                const WindingEstimate<double> e = certified_winding_number(sah.view(), p[k], sah.options().accuracy);
                ASSERT_EQ(std::memcmp(&value[k], &e.value, sizeof(double)), 0) << c.mesh.name();
                ASSERT_EQ(std::memcmp(&bound[k], &e.error_bound, sizeof(double)), 0) << c.mesh.name();
            }
        }
    }
}

TEST(CertifiedWindingSign, SolidAngleBoundCoversPointsOnTheTriangle) {
    const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
    double err;
    certified_solid_angle(Vec3d{0.25, 0.25, 0.0}, a, b, c, err);
    EXPECT_GE(err, 4 * kWindingPi);  // on the triangle: +-2 pi, undecidable
    certified_solid_angle(Vec3d{0.25, 0.25, 1e-300}, a, b, c, err);
    EXPECT_GE(err, 4 * kWindingPi);
    certified_solid_angle(Vec3d{0.25, 0.25, 0.5}, a, b, c, err);
    EXPECT_LT(err, 1e-13);
}

}  // namespace
}  // namespace sdf
