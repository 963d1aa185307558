#include "cpu_reference/raycast/mesh_reference.h"

#include <chrono>
#include <limits>

#include "core/parallel/parallel_for.h"
#include "cpu_reference/raycast/tile_loop.h"
#include "kernels/bvh/ray_traversal.h"
#include "kernels/raycast/cast_pixel.h"
#include "kernels/raycast/ray_triangle.h"

namespace sdf {

MeshReferenceRenderer::MeshReferenceRenderer(const PreparedMesh& mesh) : mesh_(mesh), bvh_(mesh.bvh()) {
    corners_.reserve(bvh_->triangle_index.size() * 3);
    for (int32_t t : bvh_->triangle_index) {
        const Int3 tri = mesh.triangles()[size_t(t)];
        for (int k = 0; k < 3; ++k) corners_.push_back(mesh.vertices()[size_t(tri[k])]);
    }
}

PixelRecord MeshReferenceRenderer::cast(const Ray<double>& ray, const Vec3d& key_light, bool interpolate_normals,
                                        int* triangle) const {
    const WatertightRay<double> w = make_watertight_ray(ray);
    TriangleHit<double> best;
    int32_t best_slot = -1;
    closest_hit_bvh(bvh_->nodes.data(), ray, std::numeric_limits<double>::infinity(),
                    [&](int32_t first, int32_t count, double& t_max) {
                        for (int32_t s = first; s < first + count; ++s) {
                            TriangleHit<double> h;
                            const Vec3d* c = &corners_[size_t(s) * 3];
                            if (intersect_watertight(w, c[0], c[1], c[2], t_max, &h)) {
                                best = h;
                                best_slot = s;
                                t_max = h.t;
                            }
                        }
                    });
    if (triangle) *triangle = best_slot < 0 ? -1 : bvh_->triangle_index[size_t(best_slot)];
    if (best_slot < 0) return background_pixel();
    const int32_t t = bvh_->triangle_index[size_t(best_slot)];
    Vec3d n = mesh_.face_normals()[size_t(t)];
    if (interpolate_normals) {
        const Int3 tri = mesh_.triangles()[size_t(t)];
        n = mesh_.vertex_normals()[size_t(tri.x)] * best.b0 + mesh_.vertex_normals()[size_t(tri.y)] * best.b1 +
            mesh_.vertex_normals()[size_t(tri.z)] * best.b2;
    }
    return shade_hit(ray, HitKind::Surface, best.t, n, key_light);
}

RenderedImage MeshReferenceRenderer::render(const CameraSpec& camera, const MeshRenderOptions& options) const {
    const PinholeCamera<double> pinhole = make_camera(camera);
    const Vec3d key = key_light_direction(pinhole);
    RenderedImage image(camera.width, camera.height);
    const auto start = std::chrono::steady_clock::now();
    for_each_tile(image.width, image.height, options.tile, options.threads, "render mesh " + mesh_.name(),
                  options.progress, [&](int x0, int y0, int x1, int y1) {
                      for (int y = y0; y < y1; ++y)
                          for (int x = x0; x < x1; ++x)
                              image.at(x, y) = cast(pinhole.generate_ray(x, y), key, options.interpolate_normals);
                  });
    image.info = {{"renderer", "mesh_reference"},
                  {"backend", "cpu"},
                  {"precision", "double"},
                  {"threads", resolve_thread_count(options.threads)},
                  {"mesh", {{"name", mesh_.name()}, {"sha256", mesh_.content_sha256()},
                            {"triangles", mesh_.triangles().size()}}},
                  {"normals", options.interpolate_normals ? "interpolated_vertex" : "face"},
                  {"intersection", "watertight (Woop et al. 2013), double, BVH"},
                  {"camera", camera_to_json(camera)},
                  {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}};
    return image;
}

RenderedImage render_mesh_reference(const PreparedMesh& mesh, const CameraSpec& camera, const MeshRenderOptions& options) {
    return MeshReferenceRenderer(mesh).render(camera, options);
}

}  // namespace sdf
