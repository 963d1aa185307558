// Cameras: pixel rays, named views fitted to bounds (every corner in the frame, the margin
// kept), explicit cameras, the dragon presets, and the errors for degenerate input.
#include <gtest/gtest.h>

#include <cmath>

#include "core/raycast/views.h"

namespace sdf {
namespace {

Bounds3 box(Vec3d lo, Vec3d hi) {
    Bounds3 b;
    b.extend(lo);
    b.extend(hi);
    return b;
}

/// Pixel coordinates (continuous, 0..width) of a world point seen by `c`.
Vec3d project(const PinholeCamera<double>& c, const Vec3d& p) {
    const Vec3d q = p - c.eye;
    const double z = dot(q, c.forward);
    const double sx = dot(q, c.right_axis()) / z / length(c.right);
    const double sy = dot(q, c.up_axis()) / z / length(c.up);
    return {(sx + 1) * 0.5 * c.width, (1 - sy) * 0.5 * c.height, z};
}

TEST(Views, PixelRaysGoThroughPixelCentres) {
    const PinholeCamera<double> c = make_look_at_camera<double>({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 90.0, 4, 2);
    // Width 4, height 2, fov_y 90: tan = 1 vertically, 2 horizontally
    const Ray<double> r = c.generate_ray(0, 0);  // top-left pixel centre: sx = -0.75, sy = 0.5
    const Vec3d expected = normalize_or_zero(Vec3d(-0.75 * 2, 0.5, -1));
    EXPECT_NEAR(r.direction.x, expected.x, 1e-12);
    EXPECT_NEAR(r.direction.y, expected.y, 1e-12);
    EXPECT_NEAR(r.direction.z, expected.z, 1e-12);
    EXPECT_NEAR(length(r.direction), 1.0, 1e-12);
}

TEST(Views, NamedViewsFitEveryCornerWithTheMargin) {
    const Bounds3 b = box({-0.1, 0.05, -0.05}, {0.1, 0.2, 0.04});  // dragon-like proportions
    for (const std::string& name : named_view_names()) {
        for (const auto& size : {std::pair<int, int>{512, 512}, {640, 360}}) {
            const CameraSpec spec = resolve_view(named_view(name), b, size.first, size.second);
            const PinholeCamera<double> c = make_camera(spec);
            double min_x = 1e9, max_x = -1e9, min_y = 1e9, max_y = -1e9;
            for (int k = 0; k < 8; ++k) {
                const Vec3d corner{k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y, k & 4 ? b.max.z : b.min.z};
                const Vec3d p = project(c, corner);
                ASSERT_GT(p.z, 0) << name;
                min_x = std::min(min_x, p.x); max_x = std::max(max_x, p.x);
                min_y = std::min(min_y, p.y); max_y = std::max(max_y, p.y);
            }
            const double mx = 0.04 * spec.width, my = 0.04 * spec.height;
            EXPECT_GE(min_x, mx - 1e-6) << name;
            EXPECT_LE(max_x, spec.width - mx + 1e-6) << name;
            EXPECT_GE(min_y, my - 1e-6) << name;
            EXPECT_LE(max_y, spec.height - my + 1e-6) << name;
            // Tight: some corner touches the margin on one axis
            const double slack = std::min({min_x - mx, spec.width - mx - max_x, min_y - my, spec.height - my - max_y});
            EXPECT_LT(slack, 1e-6) << name;
            EXPECT_NEAR(length(spec.target - b.center()), 0.0, 1e-12) << name;
        }
    }
}

TEST(Views, FittingPointsIsTighterThanTheirBoxAndKeepsThemInside) {
    std::vector<Vec3d> points;  // a sphere's points: its box corners stick out in oblique views
    for (int i = 0; i < 400; ++i) {
        const double t = std::acos(1 - 2 * (i + 0.5) / 400), p = 2.399963 * i;
        points.push_back(Vec3d(std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)) * 0.5);
    }
    Bounds3 b;
    for (const Vec3d& p : points) b.extend(p);
    const CameraSpec loose = resolve_view(named_view("three_quarter"), b, 200, 200);
    const CameraSpec tight = resolve_view(named_view("three_quarter"), points, 200, 200);
    EXPECT_LT(length(tight.eye - tight.target), 0.8 * length(loose.eye - loose.target));
    const PinholeCamera<double> c = make_camera(tight);
    for (const Vec3d& p : points) {
        const Vec3d q = project(c, p);
        EXPECT_GE(q.x, 0.04 * 200 - 1e-6);
        EXPECT_LE(q.x, 200 - 0.04 * 200 + 1e-6);
        EXPECT_GE(q.y, 0.04 * 200 - 1e-6);
        EXPECT_LE(q.y, 200 - 0.04 * 200 + 1e-6);
    }
}

TEST(Views, DragonPresetsAndExplicitCameras) {
    const Bounds3 b = box({-1, -1, -1}, {1, 1, 1});
    const CameraSpec side = resolve_view(named_view("dragon_side"), b, 100, 100);
    EXPECT_GT(side.eye.z, 1.0);
    EXPECT_NEAR(side.eye.x, 0.0, 1e-12);
    const CameraSpec front = resolve_view(named_view("dragon_front"), b, 100, 100);
    EXPECT_GT(std::abs(front.eye.x), 1.0);
    ViewRequest r;
    r.name = "mine";
    r.explicit_camera = true;
    r.eye = {1, 2, 3};
    r.target = {0, 0.5, 0};
    r.up = {0, 0, 1};
    r.fov_y_degrees = 20;
    const CameraSpec e = resolve_view(r, Bounds3{}, 64, 32);  // bounds unused for explicit cameras
    EXPECT_EQ(e.eye, Vec3d(1, 2, 3));
    EXPECT_EQ(e.up, Vec3d(0, 0, 1));
    EXPECT_EQ(e.width, 64);
    EXPECT_EQ(camera_to_json(e)["fov_y_degrees"], 20.0);
}

TEST(Views, RejectsDegenerateRequestsWithTheirValues) {
    const Bounds3 b = box({-1, -1, -1}, {1, 1, 1});
    auto message = [&](const ViewRequest& r, int w, int h) {
        try {
            resolve_view(r, b, w, h);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    EXPECT_NE(message(ViewRequest{"frnot"}, 8, 8).find("unknown view name"), std::string::npos);
    EXPECT_NE(message(named_view("front"), 0, 8).find("0x8"), std::string::npos);
    ViewRequest wide = named_view("front");
    wide.fov_y_degrees = 180;
    EXPECT_NE(message(wide, 8, 8).find("outside (0, 180)"), std::string::npos);
    ViewRequest r;
    r.name = "bad";
    r.explicit_camera = true;
    r.eye = r.target = {1, 1, 1};
    EXPECT_NE(message(r, 8, 8).find("equals target"), std::string::npos);
    r.target = {1, 0, 1};  // looking along -y with up +y
    EXPECT_NE(message(r, 8, 8).find("parallel to the view direction"), std::string::npos);
}

}  // namespace
}  // namespace sdf
