/// @file cc_finite_differences.h
/// @brief Finite differences on the CC lattice, per lattice unit (h = 1): the estimated
/// Hermite data of the tricubic schemes (thesis chapter 5: "on CC, a simple
/// finite-differencing scheme is used").
///
/// D, the 1-D derivative operator along one axis, is the central difference
/// (f[i+1] - f[i-1]) / 2 inside the grid and, on the first and last point, the derivative
/// of the same quadratic fitted to the nearest complete 3-point stencil, i.e. the one-sided
/// second-order difference (-3 f[0] + 4 f[1] - f[2]) / 2. All CC derivative data are tensor
/// products of D: fx = Dx f, fxy = Dx Dy f, fxyz = Dx Dy Dz f. Each is exact for
/// polynomials of degree <= 2 in the differentiated variables. Catmull-Rom splines are
/// cubic Hermite interpolation with exactly these data (catmull_rom.h), so tricubic_lm with
/// `fd` data reproduces catmull_rom.
#pragma once

#include "kernels/reconstruction/lattice_field_view.h"

namespace sdf {

/// Three taps (index, weight) of D at point i of an axis with n >= 3 points.
template <typename T>
struct DifferenceTaps {
    int index[3];
    T weight[3];
};

template <typename T>
SDF_CPU_GPU DifferenceTaps<T> central_difference_taps(int i, int n) {
    SDF_DCHECK(n >= 3 && i >= 0 && i < n);
    if (i == 0) return {{0, 1, 2}, {T(-1.5), T(2), T(-0.5)}};
    if (i == n - 1) return {{n - 3, n - 2, n - 1}, {T(0.5), T(-2), T(1.5)}};
    return {{i - 1, i, i + 1}, {T(-0.5), T(0), T(0.5)}};
}

/// Applies D along the axes with mask bit set (bit 0 = x, 1 = y, 2 = z) at grid point p to
/// the scalar that fetch(storage index) returns: mask 3 gives the cross derivative fxy.
template <typename T, typename Fetch>
SDF_CPU_GPU T cc_difference(const Lattice& l, const Int3& p, int mask, const Fetch& fetch) {
    DifferenceTaps<T> taps[3];
    for (int a = 0; a < 3; ++a)
        taps[a] = (mask >> a) & 1 ? central_difference_taps<T>(p[a], l.resolution[a])
                                  : DifferenceTaps<T>{{p[a], p[a], p[a]}, {T(1), T(0), T(0)}};
    T sum = T(0);
    for (int c = 0; c < 3; ++c)
        for (int b = 0; b < 3; ++b)
            for (int a = 0; a < 3; ++a) {
                const T w = taps[0].weight[a] * taps[1].weight[b] * taps[2].weight[c];
                if (w != T(0)) sum += w * fetch(cc_index(l, taps[0].index[a], taps[1].index[b], taps[2].index[c]));
            }
    return sum;
}

/// Hermite data of one CC point from values only (derivative source `fd`).
template <typename T>
struct CcHermitePoint {
    Vec3<T> first{};
    T higher[kCcHigherStride]{};
};

template <typename T>
SDF_CPU_GPU CcHermitePoint<T> cc_hermite_from_values(const Lattice& l, const T* f, const Int3& p) {
    auto d = [&](int mask) { return cc_difference<T>(l, p, mask, [&](int64_t i) { return f[i]; }); };
    CcHermitePoint<T> h;
    h.first = {d(1), d(2), d(4)};
    h.higher[kCcDxy] = d(3);
    h.higher[kCcDxz] = d(5);
    h.higher[kCcDyz] = d(6);
    h.higher[kCcDxyz] = d(7);
    return h;
}

/// Hermite data of one CC point from true first derivatives g (per lattice unit; source
/// `true`): the cross derivatives are the symmetrised differences of g,
///   fxy = (Dy gx + Dx gy) / 2,  fxyz = (Dy Dz gx + Dx Dz gy + Dx Dy gz) / 3,
/// each exact when g is the gradient of a cubic.
template <typename T>
SDF_CPU_GPU CcHermitePoint<T> cc_hermite_from_gradients(const Lattice& l, const Vec3<T>* g, const Int3& p) {
    // d(c, mask): D applied along `mask` to component c of g
    auto d = [&](int c, int mask) { return cc_difference<T>(l, p, mask, [&](int64_t i) { return g[i][c]; }); };
    CcHermitePoint<T> h;
    h.first = g[cc_index(l, p.x, p.y, p.z)];
    h.higher[kCcDxy] = T(0.5) * (d(0, 2) + d(1, 1));
    h.higher[kCcDxz] = T(0.5) * (d(0, 4) + d(2, 1));
    h.higher[kCcDyz] = T(0.5) * (d(1, 4) + d(2, 2));
    h.higher[kCcDxyz] = (d(0, 6) + d(1, 5) + d(2, 3)) / T(3);
    return h;
}

}  // namespace sdf
