// The mesh reference renderer (watertight ray-triangle test over the BVH, in double) against
// the analytic sphere an icosphere approximates, and against brute force over all triangles.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>

#include "core/mesh/shapes/procedural_shapes.h"
#include "core/raycast/image_metrics.h"
#include "cpu_reference/raycast/mesh_reference.h"
#include "kernels/raycast/ray_triangle.h"
#include "kernels/raycast/shading.h"
#include "raycast_test_util.h"

namespace sdf {
namespace {

constexpr int kSize = 128;

TEST(MeshReference, IcosphereMatchesTheAnalyticSphereSilhouette) {
    // Icosphere with 5 subdivisions (20,480 triangles): its faces lie between the sphere and
    // the sagitta s = R - min(distance from the centre to a face plane) inside it. A pixel
    // may differ from the analytic sphere only if its centre ray passes within s of the
    // sphere's silhouette (R - s <= b <= R, b = the ray's distance from the centre). Stated
    // bounds: no mismatch outside that band, and at most 20 pixels in it (measured: 16, all
    // at 6e-4 px inside the silhouette, where this symmetric view puts 16 pixel centres).
    const test::Sphere sphere;
    const PreparedMesh mesh = prepare_mesh(make_icosphere(5, sphere.radius, sphere.centre));
    double sagitta = 0;
    for (size_t t = 0; t < mesh.triangles().size(); ++t) {
        const Vec3d a = mesh.vertices()[size_t(mesh.triangles()[t].x)];
        sagitta = std::max(sagitta, sphere.radius - std::abs(dot(a - sphere.centre, mesh.face_normals()[t])));
    }
    const CameraSpec camera = resolve_view(named_view("three_quarter"), sphere.bounds(), kSize, kSize);
    MeshRenderOptions options;
    options.progress = false;
    const RenderedImage image = render_mesh_reference(mesh, camera, options);
    const PinholeCamera<double> pinhole = make_camera(camera);
    int mismatch = 0, outside_band = 0, hits = 0;
    double max_angle = 0, max_depth = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const Ray<double> ray = pinhole.generate_ray(x, y);
            const double t = sphere.intersect(ray);
            const PixelRecord& p = image.at(x, y);
            if (p.is_hit() != (t >= 0)) {
                ++mismatch;
                const Vec3d o = ray.origin - sphere.centre;
                const double b = length(o - ray.direction * dot(o, ray.direction));
                outside_band += (b < sphere.radius - sagitta || b > sphere.radius) ? 1 : 0;
            }
            if (!p.is_hit() || t < 0) continue;
            ++hits;
            // A face normal is within the angle a face subtends (~1.3 deg) of the sphere's normal
            max_angle = std::max(max_angle, angle_degrees(p.normal, Vec3f(normalize_or_zero(ray.at(t) - sphere.centre))));
            max_depth = std::max(max_depth, std::abs(double(p.depth) - t));
        }
    std::printf("icosphere(5) vs sphere: sagitta %.2e R; %d mismatched of %d hit pixels (%d outside the band); "
                "normal max %.3f deg, depth max %.2e R\n",
                sagitta / sphere.radius, mismatch, hits, outside_band, max_angle, max_depth / sphere.radius);
    EXPECT_EQ(outside_band, 0);
    EXPECT_LE(mismatch, 20);
    EXPECT_GT(hits, kSize * kSize / 8);
    EXPECT_LE(max_angle, 2.0);
    // Depth differs by at most the sagitta over the cosine of the incidence angle; near the
    // silhouette that grows, so the bound is loose: 2% of R
    EXPECT_LE(max_depth, 0.02 * sphere.radius);
}

TEST(MeshReference, InterpolatedNormalsAreSmootherThanFaceNormals) {
    const test::Sphere sphere;
    const PreparedMesh mesh = prepare_mesh(make_icosphere(3, sphere.radius, sphere.centre));
    const CameraSpec camera = resolve_view(named_view("front"), sphere.bounds(), 64, 64);
    MeshRenderOptions face, smooth;
    face.progress = smooth.progress = false;
    smooth.interpolate_normals = true;
    const MeshReferenceRenderer renderer(mesh);
    const RenderedImage a = renderer.render(camera, face), b = renderer.render(camera, smooth);
    const PinholeCamera<double> pinhole = make_camera(camera);
    double err_face = 0, err_smooth = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            if (!a.at(x, y).is_hit()) continue;
            const Ray<double> ray = pinhole.generate_ray(x, y);
            const Vec3f truth(normalize_or_zero(ray.at(double(a.at(x, y).depth)) - sphere.centre));
            err_face += angle_degrees(a.at(x, y).normal, truth);
            err_smooth += angle_degrees(b.at(x, y).normal, truth);
        }
    EXPECT_LT(err_smooth, 0.5 * err_face);
}

TEST(MeshReference, BvhTraversalFindsTheBruteForceClosestHit) {
    // Every pixel's triangle and depth equal the closest watertight hit over all triangles
    const PreparedMesh mesh = prepare_mesh(make_pawn());
    const CameraSpec camera = resolve_view(named_view("three_quarter"), mesh.bounds(), 48, 48);
    const MeshReferenceRenderer renderer(mesh);
    const PinholeCamera<double> pinhole = make_camera(camera);
    const Vec3d key = key_light_direction(pinhole);
    int hits = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x) {
            const Ray<double> ray = pinhole.generate_ray(x, y);
            int triangle = -2;
            const PixelRecord p = renderer.cast(ray, key, false, &triangle);
            const WatertightRay<double> w = make_watertight_ray(ray);
            double best = std::numeric_limits<double>::infinity();
            for (const Int3& t : mesh.triangles()) {
                TriangleHit<double> h;
                if (intersect_watertight(w, mesh.vertices()[size_t(t.x)], mesh.vertices()[size_t(t.y)],
                                         mesh.vertices()[size_t(t.z)], best, &h))
                    best = h.t;
            }
            ASSERT_EQ(p.is_hit(), best < std::numeric_limits<double>::infinity()) << x << "," << y;
            if (!p.is_hit()) continue;
            ++hits;
            EXPECT_FLOAT_EQ(p.depth, float(best));
            EXPECT_GE(triangle, 0);
        }
    EXPECT_GT(hits, 100);
}

TEST(MeshReference, WatertightTestHasNoCracksAlongSharedEdges) {
    // Rays aimed exactly at the shared edges and vertices of a closed mesh all hit
    const PreparedMesh mesh = prepare_mesh(make_icosphere(1));
    const MeshReferenceRenderer renderer(mesh);
    const Vec3d eye{0.31, 2.7, 3.3};
    int misses = 0, rays = 0;
    for (const Int3& t : mesh.triangles())
        for (int k = 0; k < 3; ++k) {
            const Vec3d a = mesh.vertices()[size_t(t[k])], b = mesh.vertices()[size_t(t[(k + 1) % 3])];
            for (const Vec3d target : {a, (a + b) * 0.5, a * 0.25 + b * 0.75}) {
                const Ray<double> ray{eye, normalize_or_zero(target - eye)};
                if (dot(ray.direction, normalize_or_zero(target)) > -0.5) continue;  // no grazing rays
                ++rays;
                misses += !renderer.cast(ray, Vec3d(0, 0, 1), false).is_hit();
            }
        }
    EXPECT_GT(rays, 50);
    EXPECT_EQ(misses, 0);
}

}  // namespace
}  // namespace sdf
