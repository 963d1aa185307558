// The point sets of core/sampling/point_sets.h against their definitions: a seed gives the
// same points; uniform_box points fill the margin-expanded box with the moments of a uniform
// distribution (mean = centre, variance = size^2 / 12); gaussian_surface points around a unit
// sphere sit at radial offsets whose mean is ~0 and whose spread is sigma x the diagonal (the
// offset's component along the normal is N(0, sigma^2), whatever the triangle).
#include <gtest/gtest.h>

#include <cmath>

#include "core/mesh/shapes/procedural_shapes.h"
#include "core/sampling/point_sets.h"

namespace sdf {
namespace {

TEST(PointSets, SameSeedSamePointsOtherSeedOtherPoints) {
    const PreparedMesh mesh = prepare_mesh(make_icosphere(2));
    for (PointSetKind kind : {PointSetKind::UniformBox, PointSetKind::GaussianSurface}) {
        PointSetSpec spec;
        spec.kind = kind;
        spec.count = 1000;
        const auto a = make_point_set(mesh, spec), b = make_point_set(mesh, spec);
        ASSERT_EQ(a.size(), 1000u);
        for (size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i].x == b[i].x && a[i].y == b[i].y && a[i].z == b[i].z);
        spec.seed = 2;
        const auto c = make_point_set(mesh, spec);
        int same = 0;
        for (size_t i = 0; i < a.size(); ++i) same += a[i].x == c[i].x;
        EXPECT_EQ(same, 0);
    }
}

TEST(PointSets, UniformBoxHasTheMomentsOfTheExpandedBox) {
    const PreparedMesh mesh = prepare_mesh(make_icosphere(2, 2.0, {1, 0, -1}));
    PointSetSpec spec;
    spec.count = 40000;
    spec.margin = 0.25;
    const auto pts = make_point_set(mesh, spec);
    const Bounds3 b = mesh.bounds();
    const double pad = 0.25 * b.extent().x;  // a sphere: every extent is the largest
    for (int a = 0; a < 3; ++a) {
        const double lo = b.min[a] - pad, size = b.extent()[a] + 2 * pad;
        double sum = 0, sq = 0;
        for (const Vec3d& p : pts) {
            ASSERT_GE(p[a], lo);
            ASSERT_LT(p[a], lo + size);
            sum += p[a];
            sq += p[a] * p[a];
        }
        const double mean = sum / double(pts.size()), var = sq / double(pts.size()) - mean * mean;
        EXPECT_NEAR(mean, lo + 0.5 * size, 0.01 * size);   // standard error: 0.0014 size
        EXPECT_NEAR(var / (size * size), 1.0 / 12.0, 0.003);  // standard error: 0.0004
    }
}

TEST(PointSets, GaussianSurfaceOffsetsHaveSigmaAlongTheNormal) {
    const PreparedMesh mesh = prepare_mesh(make_icosphere(5));  // faceting: radius within 0.1% of 1
    PointSetSpec spec;
    spec.kind = PointSetKind::GaussianSurface;
    spec.count = 40000;
    spec.sigma = 0.005;
    const double sigma = spec.sigma * mesh.bounds().diagonal();  // about 0.0173
    const auto pts = make_point_set(mesh, spec);
    double sum = 0, sq = 0;
    for (const Vec3d& p : pts) {
        const double r = length(p) - 1.0;
        sum += r;
        sq += r * r;
    }
    const double mean = sum / double(pts.size()), sd = std::sqrt(sq / double(pts.size()) - mean * mean);
    // Tangential offsets lift the radius by sigma^2 (3e-4) and facets lower it by < 1e-3.
    EXPECT_NEAR(mean, 0.0, 0.0015);
    EXPECT_NEAR(sd / sigma, 1.0, 0.03);  // standard error of the spread: 0.4%
}

TEST(PointSets, KindsAreNamedAndUnknownNamesRejected) {
    EXPECT_EQ(point_set_kind_from_name("gaussian_surface"), PointSetKind::GaussianSurface);
    try {
        point_set_kind_from_name("sphere_shell");
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("uniform_box"), std::string::npos);
    }
    PointSetSpec spec;
    spec.kind = PointSetKind::GaussianSurface;
    spec.count = 7;
    EXPECT_EQ(point_set_label(spec), "gaussian_surface(sigma=0.01)/7");
}

}  // namespace
}  // namespace sdf
