/// @file ray_box.h
/// @brief The parameter interval in which a ray lies inside an axis-aligned box (the slab
/// method, Kay & Kajiya 1986), and which face it enters through.
#pragma once

#include "kernels/raycast/camera.h"
#include "kernels/reconstruction/interpolator.h"

namespace sdf {

template <typename T>
struct RaySegment {
    bool valid = false;  ///< the ray meets the box for some t >= 0
    T t_enter{}, t_exit{};
    int enter_axis = -1;  ///< axis of the face the ray enters through; -1 when it starts inside
};

/// [t_enter, t_exit] of the ray inside `box`, with t_enter >= 0 (a ray starting inside the
/// box has t_enter = 0 and enter_axis = -1). A direction component of exactly 0 constrains
/// nothing on that axis when the origin lies within the slab, and misses otherwise.
template <typename T>
SDF_CPU_GPU RaySegment<T> clip_ray_to_box(const Ray<T>& ray, const DomainBox<T>& box) {
    RaySegment<T> s;
    T t0 = T(0), t1 = T(0);
    bool bounded = false;
    int axis0 = -1;
    for (int a = 0; a < 3; ++a) {
        const T o = ray.origin[a], d = ray.direction[a];
        if (d == T(0)) {
            if (o < box.lo[a] || o > box.hi[a]) return s;
            continue;
        }
        T near = (box.lo[a] - o) / d, far = (box.hi[a] - o) / d;
        if (near > far) { const T tmp = near; near = far; far = tmp; }
        if (!bounded || near > t0) { t0 = near; axis0 = a; }
        if (!bounded || far < t1) t1 = far;
        bounded = true;
    }
    if (!bounded) return s;  // zero direction
    if (t0 < T(0)) { t0 = T(0); axis0 = -1; }
    if (t1 < t0) return s;
    s.valid = true;
    s.t_enter = t0;
    s.t_exit = t1;
    s.enter_axis = axis0;
    return s;
}

/// Unit normal of the box face a ray enters through (pointing back at the ray), or -direction
/// for a ray that starts inside.
template <typename T>
SDF_CPU_GPU Vec3<T> entry_face_normal(const Ray<T>& ray, int enter_axis) {
    if (enter_axis < 0) return -ray.direction;
    Vec3<T> n(T(0));
    n[enter_axis] = ray.direction[enter_axis] > T(0) ? T(-1) : T(1);
    return n;
}

}  // namespace sdf
