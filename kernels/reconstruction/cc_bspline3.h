/// @file cc_bspline3.h
/// @brief The tricubic B-spline on the CC lattice with the classical interpolation
/// prefilter: s(u) = sum_k c_k beta3(u_x - k_x) beta3(u_y - k_y) beta3(u_z - k_z), with c
/// such that s interpolates the samples (Unser, Aldroubi, Eden, "B-spline signal
/// processing", IEEE TSP 41(2), 1993; Unser, "Splines: a perfect fit", IEEE SPM 16(6), 1999).
/// The Cartesian counterpart that Entezari et al. (TVCG 2008) compare the BCC quintic box
/// spline with.
///
/// beta3 is the centred cubic B-spline (support [-2, 2], C2). The coefficients c are the
/// samples filtered along each axis by the inverse of (z + 4 + 1/z)/6: one causal and one
/// anti-causal first-order recursion with pole sqrt(3) - 2, mirror boundary conditions
/// (core/reconstruction/spline_prefilters.h); they live in LatticeFieldView::higher.
/// Interpolating, C2, reproduces every cubic (per axis: every tricubic), order 4. 4x4x4 taps
/// per evaluation, mirrored at the grid's faces (spline_coefficients.h), so the domain is
/// the whole grid box; gradient and Hessian are the analytic derivatives of the weights.
#pragma once

#include "kernels/reconstruction/cc_cell.h"
#include "kernels/reconstruction/spline_coefficients.h"

namespace sdf {

/// Indices (mirrored) and weights of the 4 taps along one axis, with their first and second
/// derivatives, for cell i and local coordinate t (t may leave [0, 1]: the extended piece).
template <typename T>
struct CubicBsplineTaps {
    int index[4];
    T w[4], dw[4], d2w[4];
};

template <typename T>
SDF_CPU_GPU CubicBsplineTaps<T> cubic_bspline_taps(int i, T t, int n) {
    const T s = T(1) - t, t2 = t * t, t3 = t2 * t;
    CubicBsplineTaps<T> k;
    k.w[0] = s * s * s / T(6);
    k.w[1] = (T(3) * t3 - T(6) * t2 + T(4)) / T(6);
    k.w[2] = (T(-3) * t3 + T(3) * t2 + T(3) * t + T(1)) / T(6);
    k.w[3] = t3 / T(6);
    k.dw[0] = -s * s / T(2);
    k.dw[1] = (T(3) * t2 - T(4) * t) / T(2);
    k.dw[2] = (T(-3) * t2 + T(2) * t + T(1)) / T(2);
    k.dw[3] = t2 / T(2);
    k.d2w[0] = s;
    k.d2w[1] = T(3) * t - T(2);
    k.d2w[2] = T(1) - T(3) * t;
    k.d2w[3] = t;
    for (int a = 0; a < 4; ++a) k.index[a] = mirror_coordinate(i - 1 + a, n - 1);
    return k;
}

struct CcBspline3 {
    SDF_CPU_GPU static constexpr const char* name() { return "cc_bspline3"; }
    SDF_CPU_GPU static constexpr int radius() { return 2; }
    SDF_CPU_GPU static constexpr int order() { return 4; }
    SDF_CPU_GPU static constexpr bool interpolating() { return true; }
    SDF_CPU_GPU static constexpr LatticeType lattice_type() { return LatticeType::CC; }
    SDF_CPU_GPU static constexpr bool uses_first() { return false; }
    SDF_CPU_GPU static constexpr int higher_stride() { return 1; }
    SDF_CPU_GPU static constexpr SplinePrefilter prefilter() { return SplinePrefilter::Interpolation; }
    SDF_CPU_GPU static constexpr PointData point_data() { return spline_point_data(prefilter()); }
    SDF_CPU_GPU static constexpr int min_resolution() { return 2; }

    template <typename T>
    SDF_CPU_GPU static DomainBox<T> domain(const LatticeFieldView<T>& v) { return cc_domain(v); }

    /// The piece of the cell with lower corner `corner` at local coordinates t (outside
    /// [0,1]^3: the piece extended); world units.
    template <typename T>
    SDF_CPU_GPU static SplineJet<T> jet_in(const LatticeFieldView<T>& v, const Int3& corner, const Vec3<T>& t,
                                           bool with_hessian) {
        const Int3 r = v.lattice.resolution;
        const CubicBsplineTaps<T> kx = cubic_bspline_taps(corner.x, t.x, r.x);
        const CubicBsplineTaps<T> ky = cubic_bspline_taps(corner.y, t.y, r.y);
        const CubicBsplineTaps<T> kz = cubic_bspline_taps(corner.z, t.z, r.z);
        // Contract x, then y, then z, keeping every derivative up to second order
        T f = 0, fx = 0, fy = 0, fz = 0, fxx = 0, fyy = 0, fzz = 0, fxy = 0, fxz = 0, fyz = 0;
        for (int c = 0; c < 4; ++c) {
            T a = 0, ax = 0, ay = 0, axx = 0, ayy = 0, axy = 0;
            for (int b = 0; b < 4; ++b) {
                T s0 = 0, s1 = 0, s2 = 0;
                for (int i = 0; i < 4; ++i) {
                    const T q = v.higher[cc_index(v.lattice, kx.index[i], ky.index[b], kz.index[c])];
                    s0 += kx.w[i] * q;
                    s1 += kx.dw[i] * q;
                    s2 += kx.d2w[i] * q;
                }
                a += ky.w[b] * s0;
                ax += ky.w[b] * s1;
                ay += ky.dw[b] * s0;
                axx += ky.w[b] * s2;
                ayy += ky.d2w[b] * s0;
                axy += ky.dw[b] * s1;
            }
            f += kz.w[c] * a;
            fx += kz.w[c] * ax;
            fy += kz.w[c] * ay;
            fz += kz.dw[c] * a;
            if (with_hessian) {
                fxx += kz.w[c] * axx;
                fyy += kz.w[c] * ayy;
                fzz += kz.d2w[c] * a;
                fxy += kz.w[c] * axy;
                fxz += kz.dw[c] * ax;
                fyz += kz.dw[c] * ay;
            }
        }
        const T s = v.inv_unit * v.inv_unit;
        SplineJet<T> jet;
        jet.value = f;
        jet.gradient = Vec3<T>(fx, fy, fz) * v.inv_unit;
        jet.hessian = {fxy * s, fxz * s, fyz * s, fxx * s, fyy * s, fzz * s};
        return jet;
    }

    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate(const LatticeFieldView<T>& v, const Vec3<T>& p) {
        const CcCell<T> cell = cc_cell_at(v, p);
        const SplineJet<T> jet = jet_in(v, cell.corner, cell.t, false);
        return {jet.value, jet.gradient, cell.inside};
    }
};

}  // namespace sdf
