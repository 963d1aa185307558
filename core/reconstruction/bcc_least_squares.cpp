#include "core/reconstruction/bcc_least_squares.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sdf {

const char* sigma_units_name(SigmaUnits u) { return u == SigmaUnits::LatticeUnits ? "lattice_units" : "spacing"; }

double sigma2_in_lattice_units(const StencilWeighting& w) {
    // One unit of h is two lattice units, so sigma^2 [h^2] = 4 sigma^2 [(h/2)^2]
    return w.units == SigmaUnits::LatticeUnits ? w.sigma2 : 4.0 * w.sigma2;
}

double stencil_weight(const StencilWeighting& w, int n, const Int3& at) {
    if (!w.gaussian) return 1.0;
    if (!(w.sigma2 > 0) || !std::isfinite(w.sigma2))
        throw std::invalid_argument("Gaussian stencil weights: sigma^2 must be a positive number, got " +
                                    std::to_string(w.sigma2));
    const Int3 o = bcc_neighbour_offset(n);
    const Int3 d{o.x - at.x, o.y - at.y, o.z - at.z};
    const double r2 = double(d.x * d.x + d.y * d.y + d.z * d.z);  // lattice units^2
    return std::max(kMinStencilWeight, std::exp(-r2 / sigma2_in_lattice_units(w)));  // eq. 4-15
}

BccFitMatrix bcc_least_squares_matrix(const StencilWeighting& w, const Int3& at) {
    // Rows of W^1/2 Phi (Phi_ij = m_j(x_i), eq. 4-13) sorted by decreasing weight: Householder
    // QR with column pivoting on row-sorted data is stable for strongly graded weights
    // (Bjorck, Numerical Methods for Least Squares Problems, 4.4), where the normal
    // equations of eq. 4-13 are not.
    int order[kBccNeighbourhood];
    double weight[kBccNeighbourhood];
    for (int n = 0; n < kBccNeighbourhood; ++n) {
        order[n] = n;
        weight[n] = stencil_weight(w, n, at);
    }
    std::stable_sort(order, order + kBccNeighbourhood, [&](int a, int b) { return weight[a] > weight[b]; });
    Eigen::Matrix<double, kBccNeighbourhood, kCubicMonomials> phi;
    Eigen::Matrix<double, kBccNeighbourhood, kBccNeighbourhood> rhs = Eigen::Matrix<double, kBccNeighbourhood, kBccNeighbourhood>::Zero();
    for (int row = 0; row < kBccNeighbourhood; ++row) {
        const int n = order[row];
        const Int3 o = bcc_neighbour_offset(n);
        const double sw = std::sqrt(weight[n]);
        for (int m = 0; m < kCubicMonomials; ++m) {
            const Int3 e = cubic_monomial_exponents(m);
            phi(row, m) = sw * std::pow(double(o.x), e.x) * std::pow(double(o.y), e.y) * std::pow(double(o.z), e.z);
        }
        rhs(row, n) = sw;  // a = K y: column n of K multiplies y_n
    }
    const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, kBccNeighbourhood, kCubicMonomials>> qr(phi);
    if (qr.rank() < kCubicMonomials)
        throw std::runtime_error("27-point least-squares fit is rank deficient (rank " + std::to_string(qr.rank()) + ")");
    return qr.solve(rhs);
}

Eigen::Matrix<double, kBccNeighbourhood, 1> bcc_derivative_stencil(const StencilWeighting& w, int dx, int dy, int dz) {
    // Derivative of the fitted cubic at 0: b^T K with b = d m / d(...) at 0 (eq. 4-14)
    const int m = cubic_monomial_index(dx, dy, dz);
    if (m < 0) throw std::invalid_argument("bcc_derivative_stencil: derivative order above 3");
    const double factorial = std::tgamma(dx + 1.0) * std::tgamma(dy + 1.0) * std::tgamma(dz + 1.0);
    return factorial * bcc_least_squares_matrix(w).row(m).transpose();
}

}  // namespace sdf
