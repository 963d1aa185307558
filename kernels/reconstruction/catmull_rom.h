/// @file catmull_rom.h
/// @brief Tricubic Catmull-Rom interpolation on the CC lattice: the separable tensor product
/// of the 1-D Catmull-Rom spline (Keys' cubic convolution with a = -1/2) over the 4x4x4
/// samples around the cell. C1; reproduces quadratics, so its approximation order is 3.
///
/// Catmull-Rom is cubic Hermite interpolation with derivatives (f[i+1] - f[i-1]) / 2, so its
/// only derivative source is `fd` (cc_finite_differences.h). At the grid's first and last
/// cell the missing sample is a ghost extrapolated by the quadratic through the three
/// nearest samples, f[-1] = 3 f[0] - 3 f[1] + f[2]; the ghost's weight is folded into those
/// samples. That makes the boundary derivative the one-sided second-order difference, so
/// this filter equals tricubic_lm with `fd` data everywhere. Needs >= 3 points per axis.
#pragma once

#include "kernels/reconstruction/cc_cell.h"

namespace sdf {

/// Indices and weights (value and derivative) of the 4 taps along one axis.
template <typename T>
struct CatmullRomTaps {
    int index[4];
    T w[4];
    T dw[4];
};

/// Moves the weight of tap `ghost` onto taps a, b, c with factors 3, -3, 1.
template <typename T>
SDF_CPU_GPU void fold_ghost(CatmullRomTaps<T>& k, int ghost, int a, int b, int c) {
    const int src[3] = {a, b, c};
    const T factor[3] = {T(3), T(-3), T(1)};
    for (int m = 0; m < 3; ++m) {
        k.w[src[m]] += factor[m] * k.w[ghost];
        k.dw[src[m]] += factor[m] * k.dw[ghost];
    }
    k.w[ghost] = k.dw[ghost] = T(0);
    k.index[ghost] = k.index[a];  // any valid sample; its weight is zero
}

template <typename T>
SDF_CPU_GPU CatmullRomTaps<T> catmull_rom_taps(int i, T t, int n) {
    SDF_DCHECK(n >= 3 && i >= 0 && i <= n - 2);
    const T t2 = t * t, t3 = t2 * t;
    CatmullRomTaps<T> k{{i - 1, i, i + 1, i + 2},
                        {(-t3 + 2 * t2 - t) / 2, (3 * t3 - 5 * t2 + 2) / 2, (-3 * t3 + 4 * t2 + t) / 2, (t3 - t2) / 2},
                        {(-3 * t2 + 4 * t - 1) / 2, (9 * t2 - 10 * t) / 2, (-9 * t2 + 8 * t + 1) / 2, (3 * t2 - 2 * t) / 2}};
    if (i == 0) fold_ghost(k, 0, 1, 2, 3);          // f[-1] = 3 f[0] - 3 f[1] + f[2]
    if (i + 2 == n) fold_ghost(k, 3, 2, 1, 0);      // f[n] = 3 f[n-1] - 3 f[n-2] + f[n-3]
    return k;
}

struct CatmullRom {
    SDF_CPU_GPU static constexpr const char* name() { return "catmull_rom"; }
    SDF_CPU_GPU static constexpr int radius() { return 2; }
    SDF_CPU_GPU static constexpr int order() { return 3; }
    SDF_CPU_GPU static constexpr bool interpolating() { return true; }
    SDF_CPU_GPU static constexpr LatticeType lattice_type() { return LatticeType::CC; }
    SDF_CPU_GPU static constexpr bool uses_first() { return false; }
    SDF_CPU_GPU static constexpr int higher_stride() { return 0; }
    SDF_CPU_GPU static constexpr PointData point_data() { return PointData::Values; }
    SDF_CPU_GPU static constexpr int min_resolution() { return 3; }

    template <typename T>
    SDF_CPU_GPU static DomainBox<T> domain(const LatticeFieldView<T>& v) { return cc_domain(v); }

    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate(const LatticeFieldView<T>& v, const Vec3<T>& p) {
        const CcCell<T> cell = cc_cell_at(v, p);
        const Int3 r = v.lattice.resolution;
        const CatmullRomTaps<T> kx = catmull_rom_taps(cell.corner.x, cell.t.x, r.x);
        const CatmullRomTaps<T> ky = catmull_rom_taps(cell.corner.y, cell.t.y, r.y);
        const CatmullRomTaps<T> kz = catmull_rom_taps(cell.corner.z, cell.t.z, r.z);
        // 64 taps; the inner loop accumulates value and d/dx, the outer ones fold in y and z
        T value = 0, gx = 0, gy = 0, gz = 0;
        for (int c = 0; c < 4; ++c) {
            T vy = 0, xy = 0, yy = 0;
            for (int b = 0; b < 4; ++b) {
                T vx = 0, dx = 0;
                for (int a = 0; a < 4; ++a) {
                    const T f = v.values[cc_index(v.lattice, kx.index[a], ky.index[b], kz.index[c])];
                    vx += kx.w[a] * f;
                    dx += kx.dw[a] * f;
                }
                vy += ky.w[b] * vx;
                xy += ky.w[b] * dx;
                yy += ky.dw[b] * vx;
            }
            value += kz.w[c] * vy;
            gx += kz.w[c] * xy;
            gy += kz.w[c] * yy;
            gz += kz.dw[c] * vy;
        }
        return {value, Vec3<T>(gx, gy, gz) * v.inv_unit, cell.inside};
    }
};

}  // namespace sdf
