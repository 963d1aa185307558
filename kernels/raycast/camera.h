/// @file camera.h
/// @brief A pinhole camera and its primary rays, for host and device (pbrt-v4's
/// PerspectiveCamera reduced to what the ray caster needs: no lens, no motion).
///
/// The camera looks from `eye` along `forward`; `right` and `up` span the image plane at
/// distance 1 and are pre-scaled by tan(fov/2) (and the aspect ratio for `right`), so pixel
/// (x, y) - x to the right, y downwards, row 0 at the top - has the ray direction
///   normalize(forward + sx * right + sy * up),  sx = 2 (x + 1/2) / width - 1,
///                                               sy = 1 - 2 (y + 1/2) / height,
/// through the pixel's centre. The field of view is vertical. Directions are unit length,
/// so a ray parameter t is a distance in world units ("depth along the ray").
/// Cameras are built on the host in double (make_look_at_camera) and converted to the
/// kernel's scalar type.
#pragma once

#include <cmath>
#include <cstdint>

#include "kernels/core/vec3.h"

namespace sdf {

template <typename T>
struct Ray {
    Vec3<T> origin{};
    Vec3<T> direction{};  ///< unit length
    SDF_CPU_GPU Vec3<T> at(T t) const { return origin + direction * t; }
};

template <typename T>
struct PinholeCamera {
    Vec3<T> eye{};
    Vec3<T> forward{0, 0, -1};  ///< unit
    Vec3<T> right{1, 0, 0};     ///< unit right vector times tan(fov_y / 2) * width / height
    Vec3<T> up{0, 1, 0};        ///< unit up vector times tan(fov_y / 2)
    int width = 1, height = 1;

    SDF_CPU_GPU int64_t pixel_count() const { return int64_t(width) * height; }

    /// The primary ray through the centre of pixel (x, y).
    SDF_CPU_GPU Ray<T> generate_ray(int x, int y) const {
        const T sx = T(2) * (T(x) + T(0.5)) / T(width) - T(1);
        const T sy = T(1) - T(2) * (T(y) + T(0.5)) / T(height);
        return {eye, normalize_or_zero(forward + right * sx + up * sy)};
    }

    /// Unit camera-frame axes in world space (for lights fixed to the camera).
    SDF_CPU_GPU Vec3<T> right_axis() const { return normalize_or_zero(right); }
    SDF_CPU_GPU Vec3<T> up_axis() const { return normalize_or_zero(up); }

    template <typename U>
    SDF_CPU_GPU PinholeCamera<U> as() const {
        PinholeCamera<U> c;
        c.eye = Vec3<U>(eye);
        c.forward = Vec3<U>(forward);
        c.right = Vec3<U>(right);
        c.up = Vec3<U>(up);
        c.width = width;
        c.height = height;
        return c;
    }
};

/// A camera at `eye` looking at `target`; `up` need not be orthogonal to the view direction
/// but must not be parallel to it (the caller checks: host code throws, see views.h).
/// fov_y_degrees is the vertical field of view.
template <typename T>
SDF_CPU_GPU PinholeCamera<T> make_look_at_camera(const Vec3<T>& eye, const Vec3<T>& target, const Vec3<T>& up,
                                                 T fov_y_degrees, int width, int height) {
    PinholeCamera<T> c;
    c.eye = eye;
    c.width = width;
    c.height = height;
    c.forward = normalize_or_zero(target - eye);
    const Vec3<T> r = normalize_or_zero(cross(c.forward, up));
    const Vec3<T> u = cross(r, c.forward);
    const T tan_half = std::tan(fov_y_degrees * T(3.14159265358979323846) / T(360));
    c.up = u * tan_half;
    c.right = r * (tan_half * T(width) / T(height));
    return c;
}

}  // namespace sdf
