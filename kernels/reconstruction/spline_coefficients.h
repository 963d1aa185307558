/// @file spline_coefficients.h
/// @brief What the B-spline and box-spline filters share: where their coefficients come
/// from (the prefilter), how they are read from a LatticeFieldView, the mirror boundary,
/// and the value/gradient/Hessian jet the continuity tests measure.
///
/// A spline filter evaluates s(u) = sum_k c_k phi(u - k) over lattice points k. With no
/// prefilter c_k = f_k (the lattice values: an approximating filter). With a prefilter the
/// host computes c from f once (core/reconstruction/spline_prefilters.h) and stores
/// it in LatticeFieldView::higher, one per point (higher_stride 1):
///   quasi-interpolation: a short FIR filter that makes the scheme reproduce every
///     polynomial the spline space contains (Strang-Fix), without interpolating;
///   interpolation: the c for which s(k) = f_k at every lattice point (an IIR inverse).
///
/// Boundary: the data are extended by whole-sample mirror symmetry across the faces of the
/// primary box, f(-k) = f(k) and f(2 top - k) = f(k) per axis (top = the last coordinate),
/// Unser's convention for B-spline prefilters; mirroring keeps BCC parity (top is even), so
/// both lattices stay lattices and the filters are defined on the whole primary box.
#pragma once

#include "kernels/reconstruction/cubic_monomials.h"
#include "kernels/reconstruction/interpolator.h"
#include "kernels/reconstruction/lattice_field_view.h"

namespace sdf {

enum class SplinePrefilter : int { None, QuasiInterpolation, Interpolation };

/// The per-point data (interpolator.h) of a spline filter with prefilter p.
SDF_CPU_GPU constexpr PointData spline_point_data(SplinePrefilter p) {
    return p == SplinePrefilter::Interpolation        ? PointData::SplineInterpolation
           : p == SplinePrefilter::QuasiInterpolation ? PointData::SplineQuasiInterpolation
                                                      : PointData::Values;
}

/// Value, gradient and Hessian (world units) of a spline at a point.
template <typename T>
struct SplineJet {
    T value{};
    Vec3<T> gradient{};
    SymmetricHessian<T> hessian{};
};

/// Coordinate k mirrored into [0, top]: one reflection, enough for |k| < 2 top.
SDF_CPU_GPU inline int mirror_coordinate(int k, int top) {
    k = k < 0 ? -k : k;
    return k > top ? 2 * top - k : k;
}

/// c at storage index i: the lattice value without a prefilter, else the stored coefficient.
template <SplinePrefilter P, typename T>
SDF_CPU_GPU T spline_coefficient(const LatticeFieldView<T>& v, int64_t i) {
    SDF_DCHECK(P == SplinePrefilter::None || (v.higher != nullptr && v.higher_stride == 1));
    return P == SplinePrefilter::None ? v.values[i] : v.higher[i];
}

/// Hessian [i][j] entry of a SymmetricHessian.
template <typename T>
SDF_CPU_GPU T hessian_entry(const SymmetricHessian<T>& h, int i, int j) {
    if (i == j) return i == 0 ? h.xx : (i == 1 ? h.yy : h.zz);
    const int pair = i + j;  // 1: xy, 2: xz, 3: yz
    return pair == 1 ? h.xy : (pair == 2 ? h.xz : h.yz);
}

}  // namespace sdf
