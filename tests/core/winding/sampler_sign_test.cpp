// The sign modes in the CPU samplers (core/sampling/sampler_sign.h) against independent
// truth: on a mesh of overlapping closed parts (two spheres and a box through them, whose
// union is known analytically) sign "auto" picks the winding number with a warning that
// says why, records it in the field's provenance, and gets every point clearly inside or
// outside the union right, with distances and gradients unchanged in magnitude and
// direction; on a closed single-shell mesh "auto" is the pseudonormal sign, bit for bit,
// and a requested winding sign agrees with it away from the surface.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <sstream>
#include <thread>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/sampling/sampler_sign.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "tests/core/winding/mesh_parts.h"
#include "tests/cpu_reference/sampling/analytic_shapes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

/// Two spheres and a box through both (as in winding_number_test.cpp), with the analytic union.
struct Parts {
    TriangleMesh mesh = test::concatenated({make_icosphere(3, 0.6, {-0.5, 0, 0}), make_icosphere(3, 0.6, {0.5, 0, 0}),
                                      make_box({1.3, 0.2, 0.2}, {0, 0, 0})});
    static bool inside_union(const Vec3d& p) {
        return test::sphere_sdf(p - Vec3d{-0.5, 0, 0}, 0.6) < 0 || test::sphere_sdf(p - Vec3d{0.5, 0, 0}, 0.6) < 0 ||
               test::box_sdf(p, {1.3, 0.2, 0.2}) < 0;
    }
    /// Distance to the nearest analytic part surface; the mesh spheres lie within 0.01 of theirs.
    static double surface_distance(const Vec3d& p) {
        return std::min({std::abs(test::sphere_sdf(p - Vec3d{-0.5, 0, 0}, 0.6)),
                         std::abs(test::sphere_sdf(p - Vec3d{0.5, 0, 0}, 0.6)), std::abs(test::box_sdf(p, {1.3, 0.2, 0.2}))});
    }
};

constexpr double kClear = 0.02;  ///< points nearer a part's surface than this are not judged

using MakeSampler = std::unique_ptr<Sampler> (*)(const SamplerOptions&);

struct Backend {
    const char* name;
    MakeSampler make;
};
const Backend kCpuSamplers[] = {{"cpu/brute_force", make_cpu_brute_force_sampler}, {"cpu/bvh", make_cpu_bvh_sampler}};

SamplerOptions options(SignMode sign) {
    SamplerOptions o;
    o.precision = Precision::Double;
    o.progress = false;
    o.sign = sign;
    return o;
}

/// Runs f with std::cerr captured; returns what was written.
template <typename F>
std::string captured_cerr(F f) {
    std::ostringstream text;
    std::streambuf* old = std::cerr.rdbuf(text.rdbuf());
    try {
        f();
    } catch (...) {
        std::cerr.rdbuf(old);
        throw;
    }
    std::cerr.rdbuf(old);
    return text.str();
}

/// `a` and `b` are the same sample up to the side: equal |distance|, triangle, and gradient
/// times the sign flip.
void expect_same_up_to_sign(double da, const Vec3d& ga, int ta, double db, const Vec3d& gb, int tb) {
    ASSERT_EQ(std::abs(da), std::abs(db));
    ASSERT_EQ(ta, tb);
    const double flip = (da < 0) == (db < 0) ? 1.0 : -1.0;
    ASSERT_EQ(ga.x, flip * gb.x);
    ASSERT_EQ(ga.y, flip * gb.y);
    ASSERT_EQ(ga.z, flip * gb.z);
}

TEST(SamplerSign, AutoPicksWindingOnOverlappingPartsWithAWarning) {
    const PreparedMesh mesh = prepare_mesh(Parts().mesh);
    const Lattice lattice = fit_lattice(LatticeType::BCC, {20, 12, 24}, mesh.bounds(), 0.15);
    for (const Backend& b : kCpuSamplers) {
        SampledField winding, pseudonormal;
        const std::string warning = captured_cerr([&] { winding = b.make(options(SignMode::Auto))->bind(share(mesh))->sample(lattice); });
        EXPECT_NE(warning.find("warning: sign auto"), std::string::npos) << b.name << ": " << warning;
        EXPECT_NE(warning.find("3 shells"), std::string::npos) << b.name << ": " << warning;
        EXPECT_NE(warning.find("winding number"), std::string::npos) << b.name << ": " << warning;
        const nlohmann::json& sign = winding.sampler.details.at("sign");
        EXPECT_EQ(sign.at("requested"), "auto") << b.name;
        EXPECT_EQ(sign.at("mode"), "winding") << b.name;
        EXPECT_NE(sign.at("reason").get<std::string>().find("3 shells"), std::string::npos) << b.name;
        EXPECT_EQ(sign.at("winding").at("beta"), 2.0) << b.name;
        // The same warning for the field when it comes back from the cache.
        EXPECT_EQ("warning: " + auto_sign_warning(winding.sampler, mesh) + "\n", warning) << b.name;

        const std::string quiet =
            captured_cerr([&] { pseudonormal = b.make(options(SignMode::Pseudonormal))->bind(share(mesh))->sample(lattice); });
        EXPECT_EQ(quiet.find("warning"), std::string::npos) << b.name << ": " << quiet;
        EXPECT_EQ(pseudonormal.sampler.details.at("sign").at("mode"), "pseudonormal");
        EXPECT_EQ(auto_sign_warning(pseudonormal.sampler, mesh), "");
        EXPECT_EQ(auto_sign_warning(nlohmann::json::object(), mesh), "");  // a field sampled before sign modes

        int judged = 0, winding_wrong = 0, pseudonormal_wrong = 0, flipped = 0;
        for (int64_t i = 0; i < lattice.num_points(); ++i) {
            const size_t k = size_t(i);
            expect_same_up_to_sign(winding.distance[k], winding.gradient[k], winding.closest_triangle[k],
                                   pseudonormal.distance[k], pseudonormal.gradient[k], pseudonormal.closest_triangle[k]);
            flipped += int((winding.distance[k] < 0) != (pseudonormal.distance[k] < 0));
            const Vec3d p = lattice.position(i);
            if (Parts::surface_distance(p) < kClear) continue;
            ++judged;
            winding_wrong += int((winding.distance[k] < 0) != Parts::inside_union(p));
            pseudonormal_wrong += int((pseudonormal.distance[k] < 0) != Parts::inside_union(p));
        }
        EXPECT_GT(judged, lattice.num_points() / 2) << b.name;
        EXPECT_EQ(winding_wrong, 0) << b.name;
        // What the winding sign is for: inside one part near another's surface the
        // pseudonormal says "outside".
        EXPECT_GT(pseudonormal_wrong, 0) << b.name;
        EXPECT_GT(flipped, 0) << b.name;
    }
}

TEST(SamplerSign, QueriedPointsTakeTheWindingSignToo) {
    const PreparedMesh mesh = prepare_mesh(Parts().mesh);
    std::vector<Vec3d> points;
    for (int i = 0; i <= 60; ++i)
        for (int j = 0; j <= 6; ++j) points.push_back({-1.3 + 2.6 * i / 60.0, -0.35 + 0.7 * j / 6.0, 0.05});
    for (const Backend& b : kCpuSamplers) {
        std::vector<PointSample> winding, pseudonormal;
        captured_cerr([&] { winding = b.make(options(SignMode::Auto))->bind(share(mesh))->query(points); });
        pseudonormal = b.make(options(SignMode::Pseudonormal))->bind(share(mesh))->query(points);
        int judged = 0;
        for (size_t i = 0; i < points.size(); ++i) {
            expect_same_up_to_sign(winding[i].distance, winding[i].gradient, winding[i].triangle, pseudonormal[i].distance,
                                   pseudonormal[i].gradient, pseudonormal[i].triangle);
            if (Parts::surface_distance(points[i]) < kClear) continue;
            ++judged;
            ASSERT_EQ(winding[i].distance < 0, Parts::inside_union(points[i]))
                << b.name << " at " << points[i].x << " " << points[i].y << " " << points[i].z;
        }
        EXPECT_GT(judged, 300) << b.name;
    }
}

/// The certified winding sign's counters (SamplerReport::winding_sign) are each sampling's
/// own: one bound sampler sampling the same lattice from two threads at once, with point
/// queries between, reports every point of each field once, the same counts for both and for
/// both CPU samplers without a band (the BVH's packets decide each point at the stage the
/// brute force's point evaluation does; with one, the BVH's skipped bricks take the ladder),
/// the narrow band's skipped points included.
TEST(SamplerSign, EachSamplingCountsItsOwnPoints) {
    const PreparedMesh mesh = prepare_mesh(Parts().mesh);
    const Lattice lattice = fit_lattice(LatticeType::CC, {24, 16, 16}, mesh.bounds(), 0.15);
    std::vector<Vec3d> points;
    for (int i = 0; i < 500; ++i) points.push_back(lattice.position(i * 7 % lattice.num_points()));
    WindingSignCounts first;
    for (const Backend& b : kCpuSamplers)
        for (double band : {0.0, 0.05}) {
            SamplerOptions o = options(SignMode::Winding);
            o.band_width = band;
            o.threads = 1;
            const auto bound = b.make(o)->bind(share(mesh));
            SampledField f1, f2;
            std::thread t1([&] { f1 = bound->sample(lattice); });
            std::thread t2([&] {
                (void)bound->query(points);
                f2 = bound->sample(lattice);
                (void)bound->query(points);
            });
            t1.join();
            t2.join();
            const std::string what = std::string(b.name) + " band " + std::to_string(band);
            ASSERT_TRUE(f1.sampler.winding_sign.has_value()) << what;
            ASSERT_TRUE(f2.sampler.winding_sign.has_value()) << what;
            const WindingSignReport& c1 = *f1.sampler.winding_sign;
            const WindingSignReport& c2 = *f2.sampler.winding_sign;
            EXPECT_EQ(c1.points(), lattice.num_points()) << what;
            EXPECT_EQ(c1.fast, c2.fast) << what;
            EXPECT_EQ(c1.refined, c2.refined) << what;
            EXPECT_EQ(c1.direct, c2.direct) << what;
            EXPECT_EQ(c1.ties, c2.ties) << what;
            EXPECT_GT(c1.surface, 0) << what;  // the first stage (surface_side.h)
            EXPECT_GT(c1.fast, 0) << what;
            EXPECT_GT(c1.refined + c1.direct + c1.ties, 0) << what;  // the ladder is exercised
            EXPECT_EQ(f1.distance, f2.distance) << what;
            const WindingSignCounts c{c1.fast, c1.refined, c1.direct, c1.ties, c1.surface};
            if (band > 0) continue;  // the BVH skips bricks the brute force samples
            if (first.points() == 0) first = c;
            EXPECT_EQ(c, first) << what;
        }
    const SampledField pseudonormal = make_cpu_bvh_sampler(options(SignMode::Pseudonormal))->bind(share(mesh))->sample(lattice);
    EXPECT_FALSE(pseudonormal.sampler.winding_sign.has_value());
}

TEST(SamplerSign, ClosedSingleShellMeshKeepsThePseudonormalSign) {
    const PreparedMesh mesh = prepare_mesh(make_torus(1.0, 0.35, 48, 24));
    const Lattice lattice = fit_lattice(LatticeType::CC, {24, 24, 12}, mesh.bounds(), 0.1);
    for (const Backend& b : kCpuSamplers) {
        SampledField automatic, pseudonormal, winding;
        const std::string log = captured_cerr([&] { automatic = b.make(options(SignMode::Auto))->bind(share(mesh))->sample(lattice); });
        EXPECT_EQ(log.find("warning"), std::string::npos) << b.name << ": " << log;
        EXPECT_EQ(automatic.sampler.details.at("sign").at("mode"), "pseudonormal") << b.name;
        EXPECT_FALSE(automatic.sampler.details.at("sign").contains("winding")) << b.name;
        pseudonormal = b.make(options(SignMode::Pseudonormal))->bind(share(mesh))->sample(lattice);
        winding = b.make(options(SignMode::Winding))->bind(share(mesh))->sample(lattice);
        EXPECT_EQ(winding.sampler.details.at("sign").at("reason"), "winding requested") << b.name;
        int judged = 0;
        for (int64_t i = 0; i < lattice.num_points(); ++i) {
            const size_t k = size_t(i);
            // auto = pseudonormal here, bit for bit
            ASSERT_EQ(automatic.distance[k], pseudonormal.distance[k]) << b.name;
            ASSERT_EQ(automatic.gradient[k].x, pseudonormal.gradient[k].x) << b.name;
            ASSERT_EQ(automatic.gradient[k].y, pseudonormal.gradient[k].y) << b.name;
            ASSERT_EQ(automatic.gradient[k].z, pseudonormal.gradient[k].z) << b.name;
            expect_same_up_to_sign(winding.distance[k], winding.gradient[k], winding.closest_triangle[k],
                                   pseudonormal.distance[k], pseudonormal.gradient[k], pseudonormal.closest_triangle[k]);
            if (std::abs(pseudonormal.distance[k]) < 1e-3) continue;
            ++judged;
            ASSERT_EQ(winding.distance[k] < 0, pseudonormal.distance[k] < 0) << b.name << " point " << i;
        }
        EXPECT_GT(judged, lattice.num_points() * 9 / 10) << b.name;
    }
}

}  // namespace
}  // namespace sdf
