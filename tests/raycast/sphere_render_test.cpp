// Acceptance test of the ray caster: the exact sphere, sampled on CC 32^3 and on BCC
// 26x26x52 (about 32k samples each, the pawn's lowest thesis resolution), rendered through
// every cubic reconstruction of the thesis's grid, against the analytic sphere: the normal
// at each hit against the sphere's normal there, the hit's distance from the sphere, and
// the coverage against the analytic silhouette.
#include <gtest/gtest.h>

#include <cstdio>

#include "core/raycast/image_metrics.h"
#include "cpu_reference/raycast/render_cpu.h"
#include "raycast_test_util.h"

namespace sdf {
namespace {

struct Case {
    const char* interpolator;
    const char* derivatives;
    LatticeType lattice;
    // Stated bounds (measured values in the comments; bounds leave about 2x headroom)
    double normal_mean_degrees, normal_p95_degrees, distance_max_units;
};

constexpr Int3 kCcResolution{32, 32, 32};
constexpr Int3 kBccResolution{26, 26, 26};  // thesis notation 26x26x52
constexpr int kSize = 128;

class SphereRender : public ::testing::TestWithParam<Case> {};

TEST_P(SphereRender, MatchesTheAnalyticSphere) {
    const Case& c = GetParam();
    const test::Sphere sphere;
    const SampledField field =
        test::sphere_field(sphere, c.lattice, c.lattice == LatticeType::CC ? kCcResolution : kBccResolution);
    const Reconstruction recon(field, c.interpolator, c.derivatives);
    const CameraSpec camera = resolve_view(named_view("three_quarter"), sphere.bounds(), kSize, kSize);
    CpuRenderOptions options;
    options.progress = false;
    const RenderedImage image = render_reconstruction_cpu(recon, camera, options);

    const PinholeCamera<double> pinhole = make_camera(camera);
    const double h = field.lattice.spacing;
    std::vector<double> angles;
    double distance_max = 0;
    int mismatch = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const PixelRecord& p = image.at(x, y);
            const Ray<double> ray = pinhole.generate_ray(x, y);
            mismatch += p.is_hit() != (sphere.intersect(ray) >= 0);
            if (!p.is_hit()) continue;
            ASSERT_EQ(p.hit, HitKind::Surface) << "pixel " << x << "," << y;
            const Vec3d hit = ray.at(double(p.depth));
            const Vec3d truth = normalize_or_zero(hit - sphere.centre);
            angles.push_back(angle_degrees(p.normal, Vec3f(truth)));
            distance_max = std::max(distance_max, std::abs(length(hit - sphere.centre) - sphere.radius) / h);
        }
    const ErrorSummary normal = summarize_errors(angles);
    std::printf("%s/%s on %s: normal error mean %.4f p95 %.4f max %.4f deg; |hit - sphere| max %.2e h; "
                "coverage mismatch %d px of %zu hits\n",
                c.interpolator, c.derivatives, c.lattice == LatticeType::CC ? "CC 32^3" : "BCC 26x26x52", normal.mean,
                normal.p95, normal.max, distance_max, mismatch, angles.size());
    EXPECT_GT(angles.size(), size_t(kSize * kSize / 8));  // the sphere fills ~22% of the frame
    EXPECT_LE(normal.mean, c.normal_mean_degrees);
    EXPECT_LE(normal.p95, c.normal_p95_degrees);
    EXPECT_LE(distance_max, c.distance_max_units);
    // Silhouette pixels only: at most 1% of the sphere's hit pixels
    EXPECT_LE(mismatch, int(angles.size() / 100));
}

INSTANTIATE_TEST_SUITE_P(
    ThesisGridReconstructions, SphereRender,
    // Measured (float casts, 128x128, three-quarter view): catmull_rom and tricubic_lm/fd
    // (the same interpolant) mean 0.031, p95 0.065 deg, distance 3.8e-4 h; tricubic_lm/true
    // mean 0.0005, p95 0.0009 deg, distance 1.4e-5 h; bcc_cubic true and fd mean 0.0014,
    // p95 0.0027 deg, distance 1.7e-5 h. Stated bounds: about 2-4x the measured values.
    ::testing::Values(Case{"catmull_rom", "fd", LatticeType::CC, 0.06, 0.15, 1e-3},
                      Case{"tricubic_lm", "true", LatticeType::CC, 0.005, 0.01, 5e-5},
                      Case{"tricubic_lm", "fd", LatticeType::CC, 0.06, 0.15, 1e-3},
                      Case{"bcc_cubic", "true", LatticeType::BCC, 0.005, 0.01, 5e-5},
                      Case{"bcc_cubic", "fd", LatticeType::BCC, 0.005, 0.01, 5e-5}),
    [](const ::testing::TestParamInfo<Case>& info) {
        return std::string(info.param.interpolator) + "_" + info.param.derivatives;
    });

}  // namespace
}  // namespace sdf
