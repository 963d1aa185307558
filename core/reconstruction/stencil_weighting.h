/// @file stencil_weighting.h
/// @brief The weighting of the BCC 27-point least-squares fit (thesis eq. 4-15), without
/// Eigen, so that headers describing a reconstruction stay light: the fit itself is in
/// bcc_least_squares.h.
///
/// Gaussian weights w_i = exp(-|x_i|^2 / sigma^2), with |x_i| measured in SigmaUnits:
/// LatticeUnits are the integer units of thesis Figure 4-2 (h/2), Spacing are units of h;
/// sigma^2 = 0.5 h^2 equals 2 lattice units^2 (docs/reconstruction.md, "sigma: which unit").
#pragma once

namespace sdf {

enum class SigmaUnits { LatticeUnits, Spacing };

struct StencilWeighting {
    bool gaussian = false;       ///< false: W = I (plain least squares)
    double sigma2 = 0.5;         ///< sigma^2 of eq. 4-15, in `units`^2
    SigmaUnits units = SigmaUnits::LatticeUnits;
};

const char* sigma_units_name(SigmaUnits u);

/// sigma^2 expressed in lattice units (h/2)^2.
double sigma2_in_lattice_units(const StencilWeighting& w);

}  // namespace sdf
