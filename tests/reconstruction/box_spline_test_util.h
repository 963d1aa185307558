// Shared helpers of the spline-filter tests (bcc_box_linear, bcc_box_quintic*, cc_bspline3):
// lattice data of an analytic function with the filter's prefilter applied, evaluation by
// type, the 48 signed axis permutations, and the box spline's definition as an integral.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/reconstruction/spline_prefilters.h"
#include "kernels/reconstruction/bcc_box_linear.h"
#include "kernels/reconstruction/bcc_box_quintic.h"
#include "kernels/reconstruction/cc_bspline3.h"
#include "reconstruction_test_util.h"

namespace sdf::test {

/// f at every lattice point, and the coefficients filter I reads.
template <typename I, typename F>
HermiteData<double> spline_data(const Lattice& l, const F& f) {
    HermiteData<double> d;
    d.lattice = l;
    for (int64_t i = 0; i < l.num_points(); ++i) d.values.push_back(f(l.position(i)).value);
    build_spline_coefficients(d, I::prefilter(), 1);
    return d;
}

/// The same from raw values.
template <typename I>
HermiteData<double> spline_data_from_values(const Lattice& l, std::vector<double> values) {
    HermiteData<double> d;
    d.lattice = l;
    d.values = std::move(values);
    build_spline_coefficients(d, I::prefilter(), 1);
    return d;
}

/// Signed permutation g: (g x)_i = sign[i] x_{perm[i]}.
struct SignedPermutation {
    int perm[3];
    int sign[3];
    template <typename V>
    V apply(const V& x) const {
        V y = x;
        for (int i = 0; i < 3; ++i) y[i] = sign[i] * x[perm[i]];
        return y;
    }
};

inline std::vector<SignedPermutation> cubic_group() {
    std::vector<SignedPermutation> g;
    int p[3] = {0, 1, 2};
    do {
        for (int s = 0; s < 8; ++s)
            g.push_back({{p[0], p[1], p[2]}, {s & 1 ? -1 : 1, s & 2 ? -1 : 1, s & 4 ? -1 : 1}});
    } while (std::next_permutation(p, p + 3));
    return g;
}

// ---- The box spline's definition, integrated numerically ---------------------------------
// M_H = indicator of the parallelepiped H [0,1)^3 (columns xi1, xi2, xi3) and
// phi_{Xi u d}(y) = int_0^1 phi_Xi(y - t d) dt. The innermost integral is the exact length of
// a segment inside the parallelepiped; each outer one is split where y - t d crosses a knot
// plane L.x = 2m (L = x+-y, x+-z, y+-z), so the integrand is one polynomial per piece and
// Gauss-Legendre with enough nodes is exact up to rounding.

constexpr double kDiagonal[4][3] = {{-1, 1, 1}, {1, -1, 1}, {1, 1, -1}, {-1, -1, -1}};

/// s = H^-1 x (H symmetric, H^-1 = [[0,1,1],[1,0,1],[1,1,0]] / 2).
inline Vec3d parallelepiped_coordinates(const Vec3d& x) {
    return {(x.y + x.z) / 2, (x.x + x.z) / 2, (x.x + x.y) / 2};
}

/// Length of {t in [0,1] : y - t d in H [0,1]^3}.
inline double parallelepiped_chord(const Vec3d& y, const Vec3d& d) {
    const Vec3d a = parallelepiped_coordinates(y), b = parallelepiped_coordinates(d);
    double lo = 0, hi = 1;
    for (int i = 0; i < 3; ++i) {
        if (b[i] == 0) {
            if (a[i] < 0 || a[i] > 1) return 0;
            continue;
        }
        const double t0 = a[i] / b[i], t1 = (a[i] - 1) / b[i];
        lo = std::max(lo, std::min(t0, t1));
        hi = std::min(hi, std::max(t0, t1));
    }
    return std::max(0.0, hi - lo);
}

/// phi of the directions H, dirs[0..count): integrates along dirs[0] first.
inline double box_spline_integral(const Vec3d& y, const Vec3d* dirs, int count) {
    if (count == 1) return parallelepiped_chord(y, dirs[0]);
    const Vec3d d = dirs[0];
    const int forms[6][3] = {{1, 1, 0}, {1, -1, 0}, {1, 0, 1}, {1, 0, -1}, {0, 1, 1}, {0, 1, -1}};
    double breaks[5] = {0};
    int n = 1;
    for (const auto& L : forms) {
        const double ld = L[0] * d.x + L[1] * d.y + L[2] * d.z, ly = L[0] * y.x + L[1] * y.y + L[2] * y.z;
        if (ld == 0) continue;
        const double m = ld > 0 ? std::floor(ly / 2) : std::floor(ly / 2) + 1;
        const double t = (ly - 2 * m) / ld;
        if (t > 0 && t < 1) breaks[n++] = t;
    }
    breaks[n++] = 1;
    for (int i = 1; i < n; ++i)  // insertion sort of at most 5
        for (int j = i; j > 0 && breaks[j] < breaks[j - 1]; --j) std::swap(breaks[j], breaks[j - 1]);
    // The integrand has degree count - 1: ceil(count / 2) Gauss-Legendre nodes per piece
    static const double node3[3] = {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
    static const double weight3[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
    static const double node2[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
    static const double weight2[2] = {0.5, 0.5};
    static const double node1[1] = {0.5}, weight1[1] = {1.0};
    const int nodes = (count + 1) / 2;
    const double* node = nodes == 1 ? node1 : (nodes == 2 ? node2 : node3);
    const double* weight = nodes == 1 ? weight1 : (nodes == 2 ? weight2 : weight3);
    double sum = 0;
    for (int piece = 0; piece + 1 < n; ++piece) {
        const double a = breaks[piece], width = breaks[piece + 1] - a;
        for (int q = 0; q < nodes; ++q)
            sum += width * weight[q] * box_spline_integral(y - d * (a + width * node[q]), dirs + 1, count - 1);
    }
    return sum;
}

/// phi4 and phi8 from the definition (the eight directions sum to 0: centred at the origin).
inline double phi4_by_integration(const Vec3d& x) {
    const Vec3d dirs[1] = {Vec3d(kDiagonal[3][0], kDiagonal[3][1], kDiagonal[3][2])};
    return box_spline_integral(x, dirs, 1);
}

inline double phi8_by_integration(const Vec3d& x) {
    Vec3d dirs[5];
    const int order[5] = {3, 0, 1, 2, 3};
    for (int i = 0; i < 5; ++i) dirs[i] = Vec3d(kDiagonal[order[i]][0], kDiagonal[order[i]][1], kDiagonal[order[i]][2]);
    return box_spline_integral(x, dirs, 5);
}

}  // namespace sdf::test
