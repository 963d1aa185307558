#include "core/bvh/search_bound.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/parallel/parallel_for.h"

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

/// The share of rho of double's slivers searched through their interior
/// (sliver_squared_distance, packed_triangle.h): each edge function is off by at most about
/// 24 u M in distance, and a point misjudged by it lies within (2 x that) / sin of the
/// triangle (sin: of its smallest angle); (64 u)^2 / S covers it, S their smallest sin^2
/// (at least kRobustSliverSin2, so at most 2^-47).
double rho_of_slivers(double smallest_sin2) {
    const double error = 64.0 * 0x1p-53;
    return smallest_sin2 < 1.0 ? error * error / smallest_sin2 : 0.0;
}

}  // namespace

FloatSearchBound float_search_bound(const std::vector<Vec3d>& vertices, const std::vector<Int3>& triangles,
                                    const DefaultInitVector<PackedTriangle<double>>& packed_double,
                                    const DefaultInitVector<PackedTriangle<float>>& packed_float, int threads) {
    // Smallest sin^2 of the triangles each precision searches inside (pack_triangle; sb NaN:
    // edges only). Float-only slivers carry their own bound (sliver_excess). Minima and
    // maxima of non-NaN values: the same whatever the chunks.
    struct Extremes {
        double sin2_float = 1.0, sin2_double = 1.0, sin2_sliver = 1.0, longest = 0.0, coordinate = 0.0;
        double reach_float = 0.0, reach_double = 0.0;  ///< squared inradii of edges-only slivers
    };
    constexpr int64_t kChunk = 16384;
    const int64_t n = int64_t(triangles.size()), nv = int64_t(vertices.size());
    const int64_t chunks = std::max<int64_t>(1, (std::max(n, nv) + kChunk - 1) / kChunk);
    std::vector<Extremes> part(static_cast<size_t>(chunks));
    parallel_for(chunks, 1, threads, [&](int64_t k0, int64_t k1) {
        for (int64_t k = k0; k < k1; ++k) {
            Extremes& x = part[size_t(k)];
            for (int64_t i = k * kChunk; i < std::min(n, (k + 1) * kChunk); ++i) {
                const Int3 t = triangles[size_t(i)];
                const Vec3d v0 = vertices[size_t(t.x)], e0 = vertices[size_t(t.y)] - v0, e1 = vertices[size_t(t.z)] - v0;
                const double a = dot(e0, e0), b = dot(e0, e1), c = dot(e1, e1), g = a - 2.0 * b + c;
                x.longest = std::max(x.longest, std::sqrt(a) + std::sqrt(c));
                const PackedTriangle<double>& pd = packed_double[size_t(i)];
                x.reach_float = std::max(x.reach_float, double(sliver_excess(packed_float[size_t(i)])));
                if (std::isnan(pd.sb) && !is_interior_sliver(pd)) {  // double's edges-only sliver
                    const double area2 = length(accurate_triangle_cross(vertices[size_t(t.x)], vertices[size_t(t.y)], vertices[size_t(t.z)]));
                    const double perimeter = std::sqrt(a) + std::sqrt(c) + std::sqrt(g);
                    if (perimeter > 0.0) x.reach_double = std::max(x.reach_double, area2 / perimeter * (area2 / perimeter));
                }
                if (is_interior_sliver(pd)) {  // its own sin^2, from its accurate area (ta = 2 |E0 x E1|)
                    const double area2 = 0.5 * pd.ta;
                    x.sin2_sliver = std::min(x.sin2_sliver, detail::smallest_sin2(area2 * area2, pd.a, pd.c, pd.g));
                }
                if (std::isnan(pd.sb)) continue;  // a sliver: never "inside" in either precision's branch-free form
                const double det = a * c - b * b;
                const double sin2 = std::min({det / (a * c), det / (a * g), det / (c * g)});
                x.sin2_double = std::min(x.sin2_double, sin2);
                if (!std::isnan(packed_float[size_t(i)].sb)) x.sin2_float = std::min(x.sin2_float, sin2);
            }
            for (int64_t i = k * kChunk; i < std::min(nv, (k + 1) * kChunk); ++i) {
                const Vec3d& v = vertices[size_t(i)];
                x.coordinate = std::max(x.coordinate, std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}));
            }
        }
    });
    double sin2_float = 1.0, sin2_double = 1.0, sin2_sliver = 1.0, longest = 0.0, coordinate = 0.0;
    double reach_float = 0.0, reach_double = 0.0;
    for (const Extremes& x : part) {
        reach_float = std::max(reach_float, x.reach_float);
        reach_double = std::max(reach_double, x.reach_double);
        sin2_sliver = std::min(sin2_sliver, x.sin2_sliver);
        sin2_float = std::min(sin2_float, x.sin2_float);
        sin2_double = std::min(sin2_double, x.sin2_double);
        longest = std::max(longest, x.longest);
        coordinate = std::max(coordinate, x.coordinate);
    }
    // pack_triangle() computes the same sin^2 in double; the margins cover its rounding.
    FloatSearchBound b;
    const double slivers = rho_of_slivers(sin2_sliver * (1.0 - 1e-6));
    b.rho = rho_of(0x1p-24, sin2_float * (1.0 - 1e-6)) + rho_of(0x1p-53, sin2_double * (1.0 - 1e-6)) +
            3.0 * (0x1p-24 + 0x1p-53);
    b.rho_double = rho_of(0x1p-53, sin2_double * (1.0 - 1e-6)) + 3.0 * 0x1p-53;
    if (slivers > 0.0) {  // added only where there are some, so every other mesh's bound keeps its bits
        b.rho += slivers;
        b.rho_double += slivers;
    }
    b.two_l = 2.0 * longest;
    b.sliver_reach_float = std::sqrt(reach_float) * 1.01;  // the inradius, rounded up
    b.sliver_reach_double = std::sqrt(reach_double) * 1.01;
    b.coordinate = coordinate;
    b.usable = std::isfinite(b.two_l) && std::isfinite(b.coordinate) && std::sqrt(2.0 * b.rho) < 0.25;
    return b;
}

}  // namespace sdf
