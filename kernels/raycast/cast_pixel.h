/// @file cast_pixel.h
/// @brief One pixel of a ray-cast reconstruction: primary ray (camera.h), march to the zero
/// level set (march.h), Blinn-Phong shading with the reconstructed gradient as the normal
/// (shading.h). The CPU driver (cpu_reference/raycast/render_cpu.h) and the CUDA kernel
/// (cuda/raycast/raycast.cu) both call cast_pixel, so the two backends share every line of
/// the per-pixel work.
#pragma once

#include "kernels/raycast/march.h"
#include "kernels/raycast/shading.h"

namespace sdf {

/// Everything a pixel needs besides its coordinates; built once per image on the host.
template <typename T>
struct RaycastScene {
    LatticeFieldView<T> view{};
    DomainBox<T> box{};          ///< Interp::domain(view)
    PinholeCamera<T> camera{};
    Vec3<T> key_light{};         ///< key_light_direction(camera)
    MarchSettings<T> march{};
};

/// The scene of interpolator Interp for a view and a camera (host or device).
template <typename Interp, typename T>
SDF_CPU_GPU RaycastScene<T> make_raycast_scene(const LatticeFieldView<T>& view, const PinholeCamera<T>& camera,
                                               const MarchSettings<T>& march) {
    RaycastScene<T> s;
    s.view = view;
    s.box = Interp::domain(view);
    s.camera = camera;
    s.key_light = key_light_direction(camera);
    s.march = march;
    return s;
}

/// Fills a record from a hit at ray parameter t with (unnormalised) normal `n`.
template <typename T>
SDF_CPU_GPU PixelRecord shade_hit(const Ray<T>& ray, HitKind kind, T t, const Vec3<T>& n, const Vec3<T>& key_light) {
    PixelRecord p;
    p.hit = kind;
    p.depth = float(t);
    const Vec3<T> facing = face_forward(n, -ray.direction);
    p.normal = Vec3f(facing);
    p.shade = float(shade_blinn_phong(facing, ray.direction, key_light));
    return p;
}

/// The background record of a ray that hit nothing.
SDF_CPU_GPU inline PixelRecord background_pixel() {
    PixelRecord p;
    p.shade = ShadingConstants::background;
    return p;
}

template <typename Interp, typename T>
SDF_CPU_GPU PixelRecord cast_pixel(const RaycastScene<T>& scene, int x, int y) {
    const Ray<T> ray = scene.camera.generate_ray(x, y);
    const MarchResult<T> m = march_ray<Interp>(scene.view, scene.box, ray, scene.march);
    PixelRecord p = m.hit == HitKind::Miss ? background_pixel() : shade_hit(ray, m.hit, m.t, m.gradient, scene.key_light);
    p.steps = uint16_t(m.steps < 65535 ? m.steps : 65535);
    p.refine_iterations = uint8_t(m.refine_iterations < 255 ? m.refine_iterations : 255);
    return p;
}

}  // namespace sdf
