/// @file vec3.h
/// @brief A small 3-vector for host and device code, templated on the scalar type.
///
/// Kept deliberately tiny (pbrt-v4's Vector3 is the model): the distance, lattice and
/// reconstruction kernels need component access, arithmetic, dot and cross products.
#pragma once

#include <cmath>

#include "kernels/core/host_device.h"

namespace sdf {

template <typename T>
struct Vec3 {
    T x{}, y{}, z{};

    Vec3() = default;
    SDF_CPU_GPU constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    SDF_CPU_GPU constexpr explicit Vec3(T v) : x(v), y(v), z(v) {}

    /// Converts between scalar types (e.g. double positions to float kernels).
    template <typename U>
    SDF_CPU_GPU constexpr explicit Vec3(const Vec3<U>& o)
        : x(static_cast<T>(o.x)), y(static_cast<T>(o.y)), z(static_cast<T>(o.z)) {}

    SDF_CPU_GPU constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    SDF_CPU_GPU T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    SDF_CPU_GPU constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    SDF_CPU_GPU constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    SDF_CPU_GPU constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    SDF_CPU_GPU constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
    SDF_CPU_GPU constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
    SDF_CPU_GPU Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
    SDF_CPU_GPU Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
    SDF_CPU_GPU Vec3& operator*=(T s) { x *= s; y *= s; z *= s; return *this; }
    SDF_CPU_GPU constexpr bool operator==(const Vec3& o) const { return x == o.x && y == o.y && z == o.z; }
    SDF_CPU_GPU constexpr bool operator!=(const Vec3& o) const { return !(*this == o); }
};

template <typename T>
SDF_CPU_GPU constexpr Vec3<T> operator*(T s, const Vec3<T>& v) { return v * s; }

template <typename T>
SDF_CPU_GPU constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

template <typename T>
SDF_CPU_GPU constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <typename T>
SDF_CPU_GPU constexpr T length_squared(const Vec3<T>& v) { return dot(v, v); }

template <typename T>
SDF_CPU_GPU T length(const Vec3<T>& v) { return std::sqrt(dot(v, v)); }

/// Unit vector along v, or the zero vector when v has zero length.
template <typename T>
SDF_CPU_GPU Vec3<T> normalize_or_zero(const Vec3<T>& v) {
    T len = length(v);
    return len > T(0) ? v / len : Vec3<T>(T(0));
}

template <typename T>
SDF_CPU_GPU constexpr Vec3<T> component_min(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z};
}

template <typename T>
SDF_CPU_GPU constexpr Vec3<T> component_max(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z};
}

template <typename T>
SDF_CPU_GPU constexpr Vec3<T> component_mul(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

/// Integer triple: lattice indices, resolutions, triangle vertex ids.
struct Int3 {
    int x{}, y{}, z{};
    SDF_CPU_GPU constexpr int operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    SDF_CPU_GPU int& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    SDF_CPU_GPU constexpr bool operator==(const Int3& o) const { return x == o.x && y == o.y && z == o.z; }
    SDF_CPU_GPU constexpr bool operator!=(const Int3& o) const { return !(*this == o); }
};

}  // namespace sdf
