#include "core/bvh/search_bound.h"

#include <algorithm>
#include <cmath>

namespace sdf {
namespace {

/// Higham's gamma_n = n u / (1 - n u).
double gamma_n(int n, double u) { return n * u / (1.0 - n * u); }

/// The share of rho (search_certificate.h) of one precision with unit roundoff u: the
/// arithmetic (gamma_32) and the misclassified branch ((8 gamma_5 / S)^2, with the double
/// constants' own relative error 4 u_double / S folded into gamma_5's unit).
double rho_of(double u, double smallest_sin2) {
    const double unit = u + 4.0 * 0x1p-53 / smallest_sin2;
    const double branch = 8.0 * gamma_n(5, unit) / smallest_sin2;
    return gamma_n(32, u) + branch * branch;
}

}  // namespace

FloatSearchBound float_search_bound(const std::vector<Vec3d>& vertices, const std::vector<Int3>& triangles,
                                    const std::vector<PackedTriangle<double>>& packed_double,
                                    const std::vector<PackedTriangle<float>>& packed_float) {
    // Smallest sin^2 of the triangles each precision searches inside (pack_triangle; sb NaN:
    // edges only). Float-only slivers carry their own bound (sliver_excess).
    double sin2_float = 1.0, sin2_double = 1.0, longest = 0.0, coordinate = 0.0;
    for (size_t i = 0; i < triangles.size(); ++i) {
        const Int3 t = triangles[i];
        const Vec3d v0 = vertices[size_t(t.x)], e0 = vertices[size_t(t.y)] - v0, e1 = vertices[size_t(t.z)] - v0;
        const double a = dot(e0, e0), b = dot(e0, e1), c = dot(e1, e1), g = a - 2.0 * b + c;
        longest = std::max(longest, std::sqrt(a) + std::sqrt(c));
        if (std::isnan(packed_double[i].sb)) continue;  // a sliver: never "inside" in either precision
        const double det = a * c - b * b;
        const double sin2 = std::min({det / (a * c), det / (a * g), det / (c * g)});
        sin2_double = std::min(sin2_double, sin2);
        if (!std::isnan(packed_float[i].sb)) sin2_float = std::min(sin2_float, sin2);
    }
    for (const Vec3d& v : vertices) coordinate = std::max(coordinate, std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}));
    // pack_triangle() computes the same sin^2 in double; the margins cover its rounding.
    FloatSearchBound b;
    b.rho = rho_of(0x1p-24, sin2_float * (1.0 - 1e-6)) + rho_of(0x1p-53, sin2_double * (1.0 - 1e-6)) +
            3.0 * (0x1p-24 + 0x1p-53);
    b.rho_double = rho_of(0x1p-53, sin2_double * (1.0 - 1e-6)) + 3.0 * 0x1p-53;
    b.two_l = 2.0 * longest;
    b.coordinate = coordinate;
    b.usable = std::isfinite(b.two_l) && std::isfinite(b.coordinate) && std::sqrt(2.0 * b.rho) < 0.25;
    return b;
}

}  // namespace sdf
