// Analytic signed distances of the procedural shapes, written independently of the code
// under test (Inigo Quilez's formulas), and an independent ray-parity inside test.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "kernels/core/vec3.h"

namespace sdf::test {

inline double box_sdf(const Vec3d& p, const Vec3d& half) {
    const Vec3d q{std::abs(p.x) - half.x, std::abs(p.y) - half.y, std::abs(p.z) - half.z};
    const Vec3d outside{std::max(q.x, 0.0), std::max(q.y, 0.0), std::max(q.z, 0.0)};
    return length(outside) + std::min(std::max({q.x, q.y, q.z}), 0.0);
}

inline double sphere_sdf(const Vec3d& p, double r) { return length(p) - r; }

/// Torus around the z axis.
inline double torus_sdf(const Vec3d& p, double major, double minor) {
    const double ring = std::sqrt(p.x * p.x + p.y * p.y) - major;
    return std::sqrt(ring * ring + p.z * p.z) - minor;
}

/// Inside test by counting crossings of a ray with the triangles (Moller-Trumbore, double).
/// Uses an irrational direction so the ray almost surely misses edges and vertices.
inline bool inside_by_ray_parity(const Vec3d& p, const std::vector<Vec3d>& v, const std::vector<Int3>& tris) {
    const Vec3d dir = normalize_or_zero(Vec3d{0.5772156649, 0.7071067811, 0.4142135623});
    int crossings = 0;
    for (const Int3& t : tris) {
        const Vec3d a = v[size_t(t.x)], b = v[size_t(t.y)], c = v[size_t(t.z)];
        const Vec3d e1 = b - a, e2 = c - a, h = cross(dir, e2);
        const double det = dot(e1, h);
        if (std::abs(det) < 1e-300) continue;
        const double inv = 1.0 / det;
        const Vec3d s = p - a;
        const double u = dot(s, h) * inv;
        if (u < 0 || u > 1) continue;
        const Vec3d q = cross(s, e1);
        const double w = dot(dir, q) * inv;
        if (w < 0 || u + w > 1) continue;
        if (dot(e2, q) * inv > 0) ++crossings;
    }
    return crossings % 2 == 1;
}

}  // namespace sdf::test
