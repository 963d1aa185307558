/// @file shading.h
/// @brief Blinn-Phong shading with two lights fixed to the camera, with constant,
/// documented parameters so that every image of the project is comparable (docs/raycast.md).
///
/// Blinn, "Models of light reflection for computer synthesized pictures", SIGGRAPH 1977.
/// Grey material, one scalar per pixel:
///
///   shade = ambient + sum over lights l of  I_l * (kd * max(0, n.L_l) + ks * max(0, n.H_l)^p)
///   H_l = normalize(L_l + V),  V = -ray direction (towards the eye)
///
///   ambient 0.08, kd 0.70, ks 0.20, p = 48
///   headlight: I = 0.40, L = V (a light at the eye, per pixel)
///   key light: I = 0.60, L = normalize(-0.45 right + 0.60 up + 0.66 back), fixed in the
///              camera frame: upper left, in front of the object (back = towards the eye)
///   background (misses): 1.0 (white)
///
/// The largest possible value is 0.08 + 1.0 * (0.70 + 0.20) = 0.98 (n facing both lights),
/// so no value exceeds 1 and nothing is clipped when stored in 8 bits. The normal is turned
/// toward the viewer first (n.V >= 0), so back faces and clipped caps shade like front faces.
#pragma once

#include "kernels/raycast/camera.h"

namespace sdf {

struct ShadingConstants {
    static constexpr float ambient = 0.08f;
    static constexpr float diffuse = 0.70f;
    static constexpr float specular = 0.20f;
    static constexpr float shininess = 48.0f;
    static constexpr float headlight = 0.40f;
    static constexpr float key_light = 0.60f;
    static constexpr float key_right = -0.45f, key_up = 0.60f, key_back = 0.66f;  ///< camera frame
    static constexpr float background = 1.0f;
};

/// n turned toward the viewer: -n when it faces away from `view` (unit, towards the eye);
/// a zero normal becomes `view`.
template <typename T>
SDF_CPU_GPU Vec3<T> face_forward(const Vec3<T>& n, const Vec3<T>& view) {
    const Vec3<T> u = normalize_or_zero(n);
    if (length_squared(u) == T(0)) return view;
    return dot(u, view) < T(0) ? -u : u;
}

/// The key light's direction in world space for this camera (unit).
template <typename T>
SDF_CPU_GPU Vec3<T> key_light_direction(const PinholeCamera<T>& camera) {
    using S = ShadingConstants;
    return normalize_or_zero(camera.right_axis() * T(S::key_right) + camera.up_axis() * T(S::key_up) -
                             camera.forward * T(S::key_back));
}

/// Diffuse plus specular term of one light.
template <typename T>
SDF_CPU_GPU T blinn_phong_term(const Vec3<T>& n, const Vec3<T>& light, const Vec3<T>& view) {
    using S = ShadingConstants;
    const T n_dot_l = dot(n, light);
    if (n_dot_l <= T(0)) return T(0);
    const Vec3<T> h = normalize_or_zero(light + view);
    const T n_dot_h = dot(n, h) > T(0) ? dot(n, h) : T(0);
    return T(S::diffuse) * n_dot_l + T(S::specular) * T(std::pow(n_dot_h, T(S::shininess)));
}

/// The shaded value for a unit normal `n` already facing the viewer, seen along `direction`.
template <typename T>
SDF_CPU_GPU T shade_blinn_phong(const Vec3<T>& n, const Vec3<T>& direction, const Vec3<T>& key_light) {
    using S = ShadingConstants;
    const Vec3<T> view = -direction;
    return T(S::ambient) + T(S::headlight) * blinn_phong_term(n, view, view) +
           T(S::key_light) * blinn_phong_term(n, key_light, view);
}

}  // namespace sdf
