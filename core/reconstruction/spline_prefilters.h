/// @file spline_prefilters.h
/// @brief The host-side prefilters of the spline filters: the coefficients c that
/// cc_bspline3, bcc_box_quintic and bcc_box_quintic_qi read from LatticeFieldView::higher
/// (one per point), computed once per field from the lattice values, with the mirror
/// boundary of kernels/reconstruction/spline_coefficients.h.
///
///   cc_bspline3 (interpolation): per axis, the inverse of the sampled cubic B-spline
///     (z + 4 + 1/z)/6 as a causal and an anti-causal recursion with pole sqrt(3) - 2 and
///     the exact mirror-symmetric initial values (Unser, "Splines: a perfect fit", IEEE SPM
///     16(6), 1999, Box 2; Thevenaz, Blu, Unser, "Interpolation revisited", IEEE TMI 19(7),
///     2000). O(n), exact to rounding.
///   bcc_box_quintic_qi (quasi-interpolation): c = 5/3 f - 1/12 sum of the 8 diagonal
///     neighbours (bcc_box_quintic.h explains why it reproduces cubics).
///   bcc_box_quintic (interpolation): solves A c = f, A the 15-point stencil of phi8 at the
///     lattice points (2/5, 1/20 on the diagonals, 1/30 on the axes). The BCC lattice is not
///     a tensor product, so no separable recursion exists; A's symbol is
///     B(w) = 1/5 + 2/5 c1 c2 c3 + 2/15 (c1^2 + c2^2 + c3^2) (ci = cos wi), and
///     c1^2 + c2^2 + c3^2 >= 3 |c1 c2 c3| gives B in [1/5, 1] exactly; with the mirror boundary
///     A is similar to a symmetric operator with that spectrum. Chebyshev iteration on
///     [1/5, 1] converges by (sqrt 5 - 1)/(sqrt 5 + 1) = 0.38 per stencil pass: ~30 passes to
///     1e-13.
#pragma once

#include <vector>

#include "core/reconstruction/hermite_data.h"
#include "kernels/reconstruction/spline_coefficients.h"

namespace sdf {

/// Interpolation coefficients of the tricubic B-spline on a CC lattice (>= 2 points per axis).
std::vector<double> cc_bspline3_coefficients(const Lattice& lattice, const std::vector<double>& values,
                                             int threads = 0);

/// How the BCC interpolation solve ended.
struct BccSolveReport {
    int iterations = 0;
    double relative_residual = 0;  ///< max |f - A c| / max |f|, recomputed at the end
};

/// Coefficients of the BCC quintic box spline for `prefilter` (QuasiInterpolation or
/// Interpolation) on a BCC lattice (>= 4 primary points per axis). Interpolation iterates to
/// a relative residual of 1e-13 and throws std::runtime_error if it does not get there.
std::vector<double> bcc_box_quintic_coefficients(const Lattice& lattice, const std::vector<double>& values,
                                                 SplinePrefilter prefilter, int threads = 0,
                                                 BccSolveReport* report = nullptr);

/// out = w_centre in + w_diagonal (sum over the 8 neighbours (+-1,+-1,+-1)) + w_axis (sum over
/// the 6 neighbours (+-2,0,0)...), mirror boundary: a symmetric BCC stencil.
void apply_bcc_stencil(const Lattice& lattice, const double* in, double* out, double w_centre, double w_diagonal,
                       double w_axis, int threads = 0);

/// Fills d.higher (higher_stride 1) with the coefficients of `prefilter` for d.lattice from
/// d.values: the cubic B-spline's on CC, the quintic box spline's on BCC. None: no arrays.
void build_spline_coefficients(HermiteData<double>& d, SplinePrefilter prefilter, int threads = 0);

}  // namespace sdf
