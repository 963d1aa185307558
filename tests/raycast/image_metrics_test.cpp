// Image metrics: zero for an image against itself; hand-made images with known normal,
// depth, coverage and shade differences.
#include <gtest/gtest.h>

#include <cmath>

#include "core/raycast/image_metrics.h"
#include "cpu_reference/raycast/mesh_reference.h"
#include "core/mesh/shapes/procedural_shapes.h"

namespace sdf {
namespace {

PixelRecord hit(float depth, Vec3f normal, float shade) {
    PixelRecord p;
    p.hit = HitKind::Surface;
    p.depth = depth;
    p.normal = normal;
    p.shade = shade;
    return p;
}

PixelRecord miss() {
    PixelRecord p;
    p.shade = 1.0f;
    return p;
}

TEST(ImageMetrics, ARenderComparedWithItselfIsZero) {
    const PreparedMesh mesh = prepare_mesh(make_pawn());
    MeshRenderOptions options;
    options.progress = false;
    const RenderedImage image =
        render_mesh_reference(mesh, resolve_view(named_view("three_quarter"), mesh.bounds(), 64, 48), options);
    const ImageMetrics m = compare_images(image, image, 0.01);
    EXPECT_GT(m.hit_both, 200);
    EXPECT_EQ(m.hit_both, m.hit_test);
    EXPECT_EQ(m.coverage_mismatch, 0);
    EXPECT_EQ(m.coverage_mismatch_fraction, 0.0);
    EXPECT_EQ(m.normal_angle_degrees.mean, 0.0);
    EXPECT_EQ(m.normal_angle_degrees.p95, 0.0);
    EXPECT_EQ(m.normal_angle_degrees.max, 0.0);
    EXPECT_EQ(m.depth.max, 0.0);
    EXPECT_EQ(m.depth_in_units.max, 0.0);
    EXPECT_EQ(m.shade_rmse, 0.0);
}

TEST(ImageMetrics, KnownDifferences) {
    // 4x5 = 20 pixels: 18 hit in both, one hit only in the test, one only in the reference
    RenderedImage a(4, 5), b(4, 5);
    const Vec3f z(0, 0, 1);
    for (int i = 0; i < 20; ++i) {
        a.pixels[size_t(i)] = hit(2.0f, z, 0.5f);
        b.pixels[size_t(i)] = hit(2.0f, z, 0.5f);
    }
    // Pixel 0: 90 degrees apart and 0.5 deeper; the others agree
    a.pixels[0] = hit(2.5f, Vec3f(1, 0, 0), 0.5f);
    // Coverage: pixel 1 only in the test, pixel 2 only in the reference
    b.pixels[1] = miss();
    a.pixels[2] = miss();
    const ImageMetrics m = compare_images(a, b, 0.25);
    EXPECT_EQ(m.pixels, 20);
    EXPECT_EQ(m.hit_both, 18);
    EXPECT_EQ(m.only_test, 1);
    EXPECT_EQ(m.only_reference, 1);
    EXPECT_EQ(m.coverage_mismatch, 2);
    EXPECT_DOUBLE_EQ(m.coverage_mismatch_fraction, 0.1);
    EXPECT_NEAR(m.normal_angle_degrees.mean, 90.0 / 18, 1e-9);
    EXPECT_NEAR(m.normal_angle_degrees.max, 90.0, 1e-9);
    EXPECT_EQ(m.normal_angle_degrees.p95, 90.0);  // nearest rank 18 of 18 sorted values
    EXPECT_NEAR(m.depth.mean, 0.5 / 18, 1e-7);
    EXPECT_NEAR(m.depth_in_units.max, 2.0, 1e-6);
    // Shade: pixels 1 and 2 differ by 0.5 (hit 0.5 vs background 1.0)
    EXPECT_NEAR(m.shade_rmse, std::sqrt(2 * 0.25 / 20), 1e-7);
    const nlohmann::json j = metrics_to_json(m);
    EXPECT_EQ(j["coverage_mismatch"], 2);
    EXPECT_DOUBLE_EQ(j["normal_angle_degrees"]["max"].get<double>(), 90.0);
    EXPECT_TRUE(j.contains("depth_in_length_units"));
}

TEST(ImageMetrics, PercentileIsTheNearestRank) {
    std::vector<double> v;
    for (int i = 1; i <= 100; ++i) v.push_back(double(101 - i));  // 100..1
    const ErrorSummary s = summarize_errors(v);
    EXPECT_DOUBLE_EQ(s.p95, 95.0);
    EXPECT_DOUBLE_EQ(s.mean, 50.5);
    EXPECT_DOUBLE_EQ(s.max, 100.0);
    std::vector<double> empty;
    EXPECT_EQ(summarize_errors(empty).max, 0.0);
}

TEST(ImageMetrics, RejectsDifferentSizes) {
    EXPECT_THROW(compare_images(RenderedImage(2, 2), RenderedImage(2, 3)), std::invalid_argument);
}

}  // namespace
}  // namespace sdf
