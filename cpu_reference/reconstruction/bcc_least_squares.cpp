#include "cpu_reference/reconstruction/bcc_least_squares.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace sdf {

const char* sigma_units_name(SigmaUnits u) { return u == SigmaUnits::LatticeUnits ? "lattice_units" : "spacing"; }

double sigma2_in_lattice_units(const StencilWeighting& w) {
    // One unit of h is two lattice units, so sigma^2 [h^2] = 4 sigma^2 [(h/2)^2]
    return w.units == SigmaUnits::LatticeUnits ? w.sigma2 : 4.0 * w.sigma2;
}

double stencil_weight(const StencilWeighting& w, int n) {
    if (!w.gaussian) return 1.0;
    if (!(w.sigma2 > 0) || !std::isfinite(w.sigma2))
        throw std::invalid_argument("Gaussian stencil weights: sigma^2 must be a positive number, got " +
                                    std::to_string(w.sigma2));
    const Int3 o = bcc_neighbour_offset(n);
    const double r2 = double(o.x * o.x + o.y * o.y + o.z * o.z);  // lattice units^2
    return std::exp(-r2 / sigma2_in_lattice_units(w));             // eq. 4-15
}

BccFitMatrix bcc_least_squares_matrix(const StencilWeighting& w) {
    // Phi_ij = m_j(x_i) (eq. 4-13), rows scaled by sqrt(w_i)
    Eigen::Matrix<double, kBccNeighbourhood, kCubicMonomials> phi;
    Eigen::Matrix<double, kBccNeighbourhood, 1> sqrt_w;
    for (int n = 0; n < kBccNeighbourhood; ++n) {
        const Int3 o = bcc_neighbour_offset(n);
        sqrt_w(n) = std::sqrt(stencil_weight(w, n));
        for (int m = 0; m < kCubicMonomials; ++m) {
            const Int3 e = cubic_monomial_exponents(m);
            phi(n, m) = std::pow(double(o.x), e.x) * std::pow(double(o.y), e.y) * std::pow(double(o.z), e.z);
        }
    }
    const Eigen::Matrix<double, kBccNeighbourhood, kCubicMonomials> scaled = sqrt_w.asDiagonal() * phi;
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd s = svd.singularValues();
    if (s(s.size() - 1) <= 1e-12 * s(0))
        throw std::runtime_error("27-point least-squares fit is rank deficient (sigma^2 too small?)");
    const Eigen::MatrixXd pinv = svd.matrixV() * s.cwiseInverse().asDiagonal() * svd.matrixU().transpose();
    return pinv * sqrt_w.asDiagonal();  // a = K y
}

Eigen::Matrix<double, kBccNeighbourhood, 1> bcc_derivative_stencil(const StencilWeighting& w, int dx, int dy, int dz) {
    // Derivative of the fitted cubic at 0: b^T K with b = d m / d(...) at 0 (eq. 4-14)
    const int m = cubic_monomial_index(dx, dy, dz);
    if (m < 0) throw std::invalid_argument("bcc_derivative_stencil: derivative order above 3");
    const double factorial = std::tgamma(dx + 1.0) * std::tgamma(dy + 1.0) * std::tgamma(dz + 1.0);
    return factorial * bcc_least_squares_matrix(w).row(m).transpose();
}

}  // namespace sdf
