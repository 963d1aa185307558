// The marcher on analytic fields (no lattice, no interpolator under test): hit accuracy,
// the step rule's guarantee (a solid as thick as the floor step is never skipped), rays
// that start inside, misses, and the bound on the number of steps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "kernels/raycast/cast_pixel.h"

namespace sdf {
namespace {

constexpr double kUnit = 0.05;  // world length of one "lattice unit" for these fields

/// A static-interface stand-in for an interpolator: the exact sphere |p| - R in [-1, 1]^3.
struct SphereField {
    static constexpr double radius = 0.6;
    template <typename T>
    static DomainBox<T> domain(const LatticeFieldView<T>&) { return {Vec3<T>(T(-1)), Vec3<T>(T(1))}; }
    template <typename T>
    static ReconstructedSample<T> evaluate(const LatticeFieldView<T>&, const Vec3<T>& p) {
        const T r = length(p);
        return {r - T(radius), r > T(0) ? p / r : Vec3<T>(T(1), T(0), T(0)), true};
    }
};

/// A slab |x - c| <= w (negative inside); c and w are set per test.
struct SlabField {
    static inline double centre = 0, half_width = 0.01;
    template <typename T>
    static DomainBox<T> domain(const LatticeFieldView<T>&) { return {Vec3<T>(T(-1)), Vec3<T>(T(1))}; }
    template <typename T>
    static ReconstructedSample<T> evaluate(const LatticeFieldView<T>&, const Vec3<T>& p) {
        const T d = p.x - T(centre);
        return {std::abs(d) - T(half_width), Vec3<T>(d >= T(0) ? T(1) : T(-1), T(0), T(0)), true};
    }
};

LatticeFieldView<double> unit_view() {
    LatticeFieldView<double> v;
    v.unit = kUnit;
    v.inv_unit = 1 / kUnit;
    return v;
}

/// Exact first intersection of a ray with the sphere |p| = R, or -1.
double sphere_hit(const Ray<double>& ray, double radius) {
    const double b = dot(ray.origin, ray.direction);
    const double c = dot(ray.origin, ray.origin) - radius * radius;
    const double disc = b * b - c;
    if (disc < 0) return -1;
    const double t = -b - std::sqrt(disc);
    return t >= 0 ? t : -1;
}

Ray<double> ray_towards(const Vec3d& origin, const Vec3d& target) { return {origin, normalize_or_zero(target - origin)}; }

TEST(March, HitsTheSphereWithinTheRefinementTolerance) {
    const LatticeFieldView<double> view = unit_view();
    const MarchSettings<double> settings;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-0.55, 0.55);
    int hits = 0;
    for (int i = 0; i < 2000; ++i) {
        const Ray<double> ray = ray_towards({0.3, -0.2, 3.0}, {u(rng), u(rng), 0.0});
        const MarchResult<double> m = march_ray<SphereField>(view, SphereField::domain(view), ray, settings);
        const double exact = sphere_hit(ray, SphereField::radius);
        ASSERT_EQ(m.hit == HitKind::Surface, exact > 0) << "ray " << i;
        if (exact < 0) continue;
        ++hits;
        // The secant point of a bracket narrower than the tolerance: within the tolerance
        EXPECT_LE(std::abs(m.t - exact), settings.tolerance_units * kUnit) << "ray " << i;
        EXPECT_LE(m.refine_iterations, settings.max_refine_iterations);
    }
    EXPECT_GT(hits, 1000);
}

TEST(March, NeverSkipsASolidAsThickAsTheFloorStep) {
    // Stated guarantee: a negative interval at least dt_min long is found. Slabs exactly
    // dt_min thick at random positions, crossed by rays at random angles (longer chords).
    const LatticeFieldView<double> view = unit_view();
    const MarchSettings<double> settings;
    SlabField::half_width = 0.5 * settings.min_step_units * kUnit;
    std::mt19937 rng(11);
    // Rays stay inside the box up to x = 1: |y|, |z| <= 0.3 + 0.2 * 3
    std::uniform_real_distribution<double> pos(-0.8, 0.8), tilt(-0.3, 0.3), slope(-0.2, 0.2);
    for (int i = 0; i < 5000; ++i) {
        SlabField::centre = pos(rng);
        const Ray<double> ray{{-2.0, tilt(rng), tilt(rng)}, normalize_or_zero(Vec3d(1.0, slope(rng), slope(rng)))};
        const MarchResult<double> m = march_ray<SlabField>(view, SlabField::domain(view), ray, settings);
        ASSERT_EQ(m.hit, HitKind::Surface) << "slab at x = " << SlabField::centre << ", ray " << i;
        const double x = ray.at(m.t).x;
        EXPECT_NEAR(x, SlabField::centre - SlabField::half_width, settings.tolerance_units * kUnit);
    }
}

TEST(March, DipCheckFindsGrazingChordsShorterThanTheFloorStep) {
    // Rays that pass just inside the sphere: chords of 0.3..0.9 dt_min, which the floor step
    // alone may jump over; the Hermite dip check finds most of them (not a guarantee).
    const LatticeFieldView<double> view = unit_view();
    MarchSettings<double> with_dip, without_dip;
    without_dip.dip_check = false;
    const double dt_min = with_dip.min_step_units * kUnit;
    int found_with = 0, found_without = 0, total = 0;
    for (int i = 0; i < 400; ++i) {
        const double chord = dt_min * (0.3 + 0.6 * (i % 40) / 39.0);
        const double b = std::sqrt(SphereField::radius * SphereField::radius - 0.25 * chord * chord);
        const double phase = 0.013 * i;  // different step phases
        const Ray<double> ray{{-2.0 - phase, b, 0.0}, {1.0, 0.0, 0.0}};
        ++total;
        found_with += march_ray<SphereField>(view, SphereField::domain(view), ray, with_dip).hit == HitKind::Surface;
        found_without += march_ray<SphereField>(view, SphereField::domain(view), ray, without_dip).hit == HitKind::Surface;
    }
    std::printf("grazing chords found: %d of %d with the dip check, %d without\n", found_with, total, found_without);
    EXPECT_GE(found_with, found_without);
    EXPECT_GE(found_with, total * 9 / 10) << "without the dip check: " << found_without;
}

TEST(March, RaysThatStartInsideAreClippedAtTheirEntryPoint) {
    const LatticeFieldView<double> view = unit_view();
    const MarchSettings<double> settings;
    // Eye inside the solid (and the box): hit at t = 0 facing the viewer
    const Ray<double> inside{{0.1, 0.0, 0.0}, {0.0, 0.0, -1.0}};
    MarchResult<double> m = march_ray<SphereField>(view, SphereField::domain(view), inside, settings);
    EXPECT_EQ(m.hit, HitKind::Clipped);
    EXPECT_EQ(m.t, 0.0);
    EXPECT_EQ(m.gradient, Vec3d(0, 0, 1));
    // The box cuts the solid: a slab through x = 0 reaches the box faces y = +-1
    SlabField::centre = 0;
    SlabField::half_width = 0.2;
    const Ray<double> from_above{{0.0, 3.0, 0.0}, {0.0, -1.0, 0.0}};
    m = march_ray<SlabField>(view, SlabField::domain(view), from_above, settings);
    EXPECT_EQ(m.hit, HitKind::Clipped);
    EXPECT_NEAR(m.t, 2.0, 1e-12);
    EXPECT_EQ(m.gradient, Vec3d(0, 1, 0));
}

TEST(March, MissesAndStepBound) {
    const LatticeFieldView<double> view = unit_view();
    const MarchSettings<double> settings;
    // Misses the box entirely
    const Ray<double> away{{0.0, 0.0, 3.0}, {0.0, 0.0, 1.0}};
    EXPECT_EQ((march_ray<SphereField>(view, SphereField::domain(view), away, settings).hit), HitKind::Miss);
    // Crosses the box outside the sphere: at most length / dt_min + 1 steps (+ dip checks)
    const Ray<double> past{{-3.0, 0.9, 0.9}, {1.0, 0.0, 0.0}};
    const MarchResult<double> m = march_ray<SphereField>(view, SphereField::domain(view), past, settings);
    EXPECT_EQ(m.hit, HitKind::Miss);
    EXPECT_LE(m.steps, int(2.0 / (settings.min_step_units * kUnit)) + 2);
    EXPECT_GT(m.steps, 2);
}

TEST(March, CastPixelShadesWithinTheDocumentedRange) {
    RaycastScene<double> scene;
    scene.view = unit_view();
    scene.box = SphereField::domain(scene.view);
    scene.camera = make_look_at_camera<double>({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 30.0, 64, 64);
    scene.key_light = key_light_direction(scene.camera);
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const PixelRecord p = cast_pixel<SphereField>(scene, x, y);
            if (!p.is_hit()) {
                EXPECT_EQ(p.shade, ShadingConstants::background);
                continue;
            }
            EXPECT_GE(p.shade, ShadingConstants::ambient - 1e-6f);
            EXPECT_LE(p.shade, 0.98f + 1e-6f);
            EXPECT_NEAR(length(p.normal), 1.0f, 1e-5f);
            EXPECT_LE(dot(Vec3d(p.normal), scene.camera.generate_ray(x, y).direction), 1e-6);  // faces the eye
        }
    // The centre pixel sees the sphere head-on: the headlight at full strength
    const PixelRecord centre = cast_pixel<SphereField>(scene, 32, 32);
    EXPECT_NEAR(centre.depth, 3.0 - SphereField::radius, 0.02);
}

}  // namespace
}  // namespace sdf
