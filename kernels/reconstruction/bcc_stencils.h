/// @file bcc_stencils.h
/// @brief Derivative estimation on the BCC lattice from values only: the (weighted)
/// least-squares cubic fitted to the 27-point neighbourhood of a lattice point, thesis
/// section 4.1.3, eqs. 4-12 to 4-15, Figure 4-2.
///
/// The fit is a = K y, with y the 27 values (in bcc_neighbour_offset order, lattice.h) and
/// K = (Phi^T W Phi)^-1 Phi^T W (eq. 4-13), a 20 x 27 matrix computed once on the host with
/// Eigen (core/reconstruction/bcc_least_squares.h). A derivative at the centre is
/// one row of K (eq. 4-14): fx = K[x], fyz = K[yz], fxx = 2 K[x^2], ...: the stencils.
/// Coordinates are the integer lattice units of Figure 4-2 (h/2), so derivatives come out
/// per h/2, the unit LatticeFieldView stores.
///
/// Boundary: a point whose 27-point neighbourhood leaves the lattice uses the nearest
/// complete neighbourhood (its centre moved inward by 2 units per axis at most, so it stays a
/// lattice point of the same kind) and differentiates that fit at its own offset. Gaussian
/// weights stay centred on the point itself, so each of the 27 possible offsets has its own
/// K (bcc_stencil_shift_index). This stays exact for cubics; it needs R >= 4 per axis.
#pragma once

#include "kernels/reconstruction/cubic_monomials.h"
#include "kernels/reconstruction/lattice_field_view.h"

namespace sdf {

constexpr int kBccNeighbourhood = 27;

/// K of eq. 4-13 (row n = coefficient of monomial n of cubic_monomials.h).
template <typename T>
struct BccLeastSquaresFit {
    T k[kCubicMonomials][kBccNeighbourhood];
};

/// Centre of the complete 27-point neighbourhood nearest to lattice point c.
SDF_CPU_GPU inline Int3 bcc_stencil_centre(const Lattice& l, const Int3& c) {
    Int3 centre = c;
    for (int a = 0; a < 3; ++a) {
        const int parity = c[a] & 1;
        const int lo = 2 + parity, hi = 2 * l.resolution[a] - 4 - parity;
        centre[a] = c[a] < lo ? lo : (c[a] > hi ? hi : c[a]);
    }
    return centre;
}

/// Which of the 27 fits lattice point c uses: 13 for an interior point (offset 0), else
/// sum over axes of (offset / 2 + 1) * 3^axis, offset = c - centre in {-2, 0, 2}.
SDF_CPU_GPU inline int bcc_stencil_shift_index(const Lattice& l, const Int3& c) {
    const Int3 centre = bcc_stencil_centre(l, c);
    return ((c.x - centre.x) / 2 + 1) + 3 * ((c.y - centre.y) / 2 + 1) + 9 * ((c.z - centre.z) / 2 + 1);
}

/// Value, gradient and Hessian of the least-squares cubic at lattice point c, per h/2.
/// `fits` holds the 27 fits indexed by bcc_stencil_shift_index (all equal when unweighted).
template <typename T>
SDF_CPU_GPU CubicJet<T> bcc_least_squares_jet(const BccLeastSquaresFit<T>* fits, const Lattice& l, const T* values,
                                              const Int3& c) {
    const Int3 centre = bcc_stencil_centre(l, c);
    const BccLeastSquaresFit<T>& fit = fits[bcc_stencil_shift_index(l, c)];
    T y[kBccNeighbourhood];
    for (int n = 0; n < kBccNeighbourhood; ++n) {
        const Int3 o = bcc_neighbour_offset(n);
        y[n] = values[bcc_index(l, {centre.x + o.x, centre.y + o.y, centre.z + o.z})];
    }
    T a[kCubicMonomials];
    for (int m = 0; m < kCubicMonomials; ++m) {
        T sum = T(0);
        for (int n = 0; n < kBccNeighbourhood; ++n) sum += fit.k[m][n] * y[n];
        a[m] = sum;
    }
    return evaluate_power_cubic(a, Vec3<T>(T(c.x - centre.x), T(c.y - centre.y), T(c.z - centre.z)));
}

}  // namespace sdf
