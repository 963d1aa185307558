/// @file exact_winding_long.h
/// @brief The brute-force exact winding number of the certified sign's tests: Van Oosterom &
/// Strackee over every triangle in long double (64-bit significand), independent of the
/// double evaluation, its trees and its bounds.
#pragma once

#include <cmath>

#include "core/mesh/prepared_mesh.h"

namespace sdf {

/// w(p) by Van Oosterom & Strackee in long double over every triangle, in mesh order.
inline long double exact_winding_long(const PreparedMesh& m, const Vec3d& p) {
    const long double pi4 = 4.0L * 3.141592653589793238462643383279502884L;
    long double sum = 0;
    for (const Int3& t : m.triangles()) {
        long double a[3], b[3], c[3];
        for (int k = 0; k < 3; ++k) {
            a[k] = (long double)m.vertices()[size_t(t.x)][k] - p[k];
            b[k] = (long double)m.vertices()[size_t(t.y)][k] - p[k];
            c[k] = (long double)m.vertices()[size_t(t.z)][k] - p[k];
        }
        auto dot = [](const long double* x, const long double* y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
        const long double bc[3] = {b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]};
        const long double la = std::sqrt(dot(a, a)), lb = std::sqrt(dot(b, b)), lc = std::sqrt(dot(c, c));
        const long double num = dot(a, bc);
        const long double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
        sum += 2.0L * std::atan2(num, den);
    }
    return sum / pi4;
}

}  // namespace sdf
