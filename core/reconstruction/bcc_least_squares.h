/// @file bcc_least_squares.h
/// @brief The 27-point least-squares cubic fit on the BCC lattice (thesis section 4.1.3,
/// eqs. 4-12 to 4-15), solved once with Eigen: the matrix K of eq. 4-13 for the kernels
/// (kernels/reconstruction/bcc_stencils.h) and the derivative stencils of eq. 4-14.
///
/// Gaussian weights (eq. 4-15): w_i = exp(-|x_i|^2 / sigma^2). sigma is measured in one of
/// two units, because the thesis does not say which: SigmaUnits::LatticeUnits are the
/// integer units of Figure 4-2 (h/2; neighbours at distance sqrt(3), 2 and 2 sqrt(2)), and
/// SigmaUnits::Spacing are units of h (the same neighbours at sqrt(3)/2, 1 and sqrt(2)).
/// sigma^2 = 0.5 h^2 equals sigma^2 = 2 in lattice units. docs/reconstruction.md explains the
/// default (lattice units, as the thesis's figure) and measures both.
///
/// Only the centred fit's even part depends on the weights: the 26 neighbours form 13
/// antipodal pairs and the odd monomials of degree <= 3 are 13, so the odd part (first and
/// third derivatives) interpolates the pair differences whatever symmetric weights are used.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "core/reconstruction/stencil_weighting.h"
#include "kernels/reconstruction/bcc_stencils.h"

namespace sdf {

/// Gaussian weights are raised to this floor so that the fit stays well conditioned: it only
/// acts where exp(-r^2 / sigma^2) < 1e-12, i.e. for sigma^2 < 0.5 (lattice units) or for the
/// off-centre fits of boundary points.
constexpr double kMinStencilWeight = 1e-12;

/// Weight of neighbour n (bcc_neighbour_offset order) for the fit evaluated at offset
/// `at` from the centre (0 except for boundary points, bcc_stencils.h).
double stencil_weight(const StencilWeighting& w, int n, const Int3& at = {0, 0, 0});

using BccFitMatrix = Eigen::Matrix<double, kCubicMonomials, kBccNeighbourhood>;

/// K = (Phi^T W Phi)^-1 Phi^T W, computed as the pseudo-inverse of W^1/2 Phi (a stable
/// route for the strongly decaying Gaussian weights).
BccFitMatrix bcc_least_squares_matrix(const StencilWeighting& w, const Int3& at = {0, 0, 0});

/// The 27 matrices for the kernels, in T, indexed by bcc_stencil_shift_index: entry i has
/// its weights centred at offset ((i % 3 - 1) * 2, (i / 3 % 3 - 1) * 2, (i / 9 - 1) * 2).
template <typename T>
std::vector<BccLeastSquaresFit<T>> bcc_least_squares_fits(const StencilWeighting& w) {
    std::vector<BccLeastSquaresFit<T>> fits(kBccNeighbourhood);
    for (int i = 0; i < kBccNeighbourhood; ++i) {
        const Int3 at{(i % 3 - 1) * 2, (i / 3 % 3 - 1) * 2, (i / 9 - 1) * 2};
        const BccFitMatrix k = bcc_least_squares_matrix(w, at);
        for (int m = 0; m < kCubicMonomials; ++m)
            for (int n = 0; n < kBccNeighbourhood; ++n) fits[size_t(i)].k[m][n] = T(k(m, n));
    }
    return fits;
}

/// The stencil of d^(dx+dy+dz) f / dx^dx dy^dy dz^dz at the centre (eq. 4-14), per lattice
/// unit h/2: weights over the 27 neighbours.
Eigen::Matrix<double, kBccNeighbourhood, 1> bcc_derivative_stencil(const StencilWeighting& w, int dx, int dy, int dz);

}  // namespace sdf
