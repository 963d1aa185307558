#include "core/reconstruction/bcc_cubic_tables.h"

#include <stdexcept>

#include "kernels/reconstruction/bcc_tetrahedron.h"
#include "kernels/reconstruction/cubic_monomials.h"

namespace sdf {
namespace {

using Vector20 = Eigen::Matrix<double, 20, 1>;
using DataVector = Eigen::Matrix<double, kBccTableColumns, 1>;

Eigen::Vector3d reference_vertex(int v) {
    return {double(bcc_reference_vertex(v, 0)), double(bcc_reference_vertex(v, 1)), double(bcc_reference_vertex(v, 2))};
}

Eigen::Vector3d barycentric_gradient(int k) {
    const Vec3d g = bcc_reference_barycentric_gradient<double>(k);
    return {g.x, g.y, g.z};
}

/// d^(dx+dy+dz) m / dx^dx dy^dy dz^dz at x: one entry per monomial.
Vector20 monomial_derivatives(const Eigen::Vector3d& x, int dx, int dy, int dz) {
    Vector20 m;
    for (int n = 0; n < kCubicMonomials; ++n) {
        const Int3 e = cubic_monomial_exponents(n);
        m(n) = monomial_derivative_1d(x.x(), e.x, dx) * monomial_derivative_1d(x.y(), e.y, dy) *
               monomial_derivative_1d(x.z(), e.z, dz);
    }
    return m;
}

/// Edge coefficient c_{2e_i + e_j} = f_i + grad f_i . (v_j - v_i) / 3 from table-order data.
double edge_coefficient(const DataVector& d, int i, int j) {
    const Eigen::Vector3d g(d(kBccData * i + kDx), d(kBccData * i + kDy), d(kBccData * i + kDz));
    return d(kBccData * i + kDf) + g.dot(reference_vertex(j) - reference_vertex(i)) / 3.0;
}

/// The three vertices of the face opposite l.
void face_vertices(int l, int f[3]) {
    for (int v = 0, n = 0; v < 4; ++v)
        if (v != l) f[n++] = v;
}

/// Face-centre coefficient of face l from p's value at the face centroid.
double face_coefficient_from_centroid(const DataVector& d, int l, double p_centroid) {
    int f[3];
    face_vertices(l, f);
    double rest = 0;
    for (int a = 0; a < 3; ++a) {
        rest += d(kBccData * f[a] + kDf);
        for (int b = 0; b < 3; ++b)
            if (a != b) rest += 3.0 * edge_coefficient(d, f[a], f[b]);
    }
    return (27.0 * p_centroid - rest) / 6.0;
}

/// Hessian at vertex v of lambda_i lambda_j lambda_k (indices may repeat).
Eigen::Matrix3d product_hessian_at_vertex(int i, int j, int k, int v) {
    const int idx[3] = {i, j, k};
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) {
            if (p == q) continue;
            const int r = 3 - p - q;  // the remaining factor, evaluated at v
            if (idx[r] == v) h += barycentric_gradient(idx[p]) * barycentric_gradient(idx[q]).transpose();
        }
    return h;
}

/// Full Hessian of vertex v from table-order data.
Eigen::Matrix3d data_hessian(const DataVector& d, int v) {
    const double* x = d.data() + kBccData * v;
    Eigen::Matrix3d h;
    h << x[kDxx], x[kDxy], x[kDxz], x[kDxy], x[kDyy], x[kDyz], x[kDxz], x[kDyz], x[kDzz];
    return h;
}

/// bcc_cubic_c0's face-centre coefficient of face l (see bcc_cubic_c0.h).
double c0_face_coefficient(const DataVector& d, int l) {
    int f[3];
    face_vertices(l, f);
    const Eigen::Vector3d n = barycentric_gradient(l).normalized();
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - n * n.transpose();
    double numerator = 0, denominator = 0;
    for (int v : f) {
        // Hessian at v of the cubic with the face centre set to 0 (face coefficients only)
        Eigen::Matrix3d h0 = Eigen::Matrix3d::Zero();
        for (int a = 0; a < 3; ++a) {
            h0 += d(kBccData * f[a] + kDf) * product_hessian_at_vertex(f[a], f[a], f[a], v);
            for (int b = 0; b < 3; ++b)
                if (a != b) h0 += 3.0 * edge_coefficient(d, f[a], f[b]) * product_hessian_at_vertex(f[a], f[a], f[b], v);
        }
        const Eigen::Matrix3d hb = 6.0 * product_hessian_at_vertex(f[0], f[1], f[2], v);
        const Eigen::Matrix3d residual = P * (data_hessian(d, v) - h0) * P, basis = P * hb * P;
        numerator += residual.cwiseProduct(basis).sum();
        denominator += basis.cwiseProduct(basis).sum();
    }
    return numerator / denominator;
}

/// Builds a 4 x 40 weight matrix column by column from a linear rule on unit data.
template <typename Rule>
BccFaceWeights weights_from_rule(const Rule& rule) {
    BccFaceWeights w;
    for (int c = 0; c < kBccTableColumns; ++c) {
        const DataVector unit = DataVector::Unit(c);
        for (int l = 0; l < 4; ++l) w(l, c) = rule(unit, l);
    }
    return w;
}

}  // namespace

BccCubicReferenceSolve solve_bcc_cubic_reference() {
    BccCubicReferenceSolve s;
    // Constraint rows (eq. 4-6) and the second-derivative monomials (eq. 4-7)
    for (int v = 0; v < 4; ++v) {
        const Eigen::Vector3d x = reference_vertex(v);
        s.M.row(4 * v + 0) = monomial_derivatives(x, 0, 0, 0).transpose();
        s.M.row(4 * v + 1) = monomial_derivatives(x, 1, 0, 0).transpose();
        s.M.row(4 * v + 2) = monomial_derivatives(x, 0, 1, 0).transpose();
        s.M.row(4 * v + 3) = monomial_derivatives(x, 0, 0, 1).transpose();
        s.N.col(3 * v + 0) = monomial_derivatives(x, 1, 1, 0);
        s.N.col(3 * v + 1) = monomial_derivatives(x, 1, 0, 1);
        s.N.col(3 * v + 2) = monomial_derivatives(x, 0, 1, 1);
    }
    s.G = s.N * s.N.transpose();
    // Particular solution a0 = M^+ f and null space Z of M
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(s.M, Eigen::ComputeFullV);
    if (svd.singularValues()(15) < 1e-9 * svd.singularValues()(0))
        throw std::runtime_error("BCC cubic: constraint matrix M of eq. 4-5 is not of rank 16");
    s.Z = svd.matrixV().rightCols(4);
    const Eigen::Matrix<double, 20, 16> m_plus = s.M.transpose() * (s.M * s.M.transpose()).inverse();
    // Eq. 4-9: (Z^T G Z) t = -Z^T (h/2 + G a0), h/2 = -N s
    const Eigen::Matrix4d zgz = s.Z.transpose() * s.G * s.Z;
    s.min_eigenvalue_ZGZ = Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(zgz).eigenvalues().minCoeff();
    if (!(s.min_eigenvalue_ZGZ > 1e-12)) throw std::runtime_error("BCC cubic: Z^T G Z of eq. 4-9 is not positive definite");
    const Eigen::Matrix4d zgz_inv = zgz.inverse();
    s.Af = (Eigen::Matrix<double, 20, 20>::Identity() - s.Z * zgz_inv * s.Z.transpose() * s.G) * m_plus;
    s.As = s.Z * zgz_inv * s.Z.transpose() * s.N;
    return s;
}

Eigen::Matrix<double, 20, 1> bcc_cubic_power_coefficients(const BccCubicReferenceSolve& solve, const DataVector& data) {
    Eigen::Matrix<double, 16, 1> f;
    Eigen::Matrix<double, 12, 1> s;
    for (int v = 0; v < 4; ++v) {
        for (int k = 0; k < 4; ++k) f(4 * v + k) = data(kBccData * v + kDf + k);
        for (int k = 0; k < 3; ++k) s(3 * v + k) = data(kBccData * v + kDxy + k);
    }
    return solve.Af * f + solve.As * s;
}

BccFaceWeights bcc_cubic_face_weights() {
    const BccCubicReferenceSolve solve = solve_bcc_cubic_reference();
    return weights_from_rule([&](const DataVector& d, int l) {
        int f[3];
        face_vertices(l, f);
        const Eigen::Vector3d centroid = (reference_vertex(f[0]) + reference_vertex(f[1]) + reference_vertex(f[2])) / 3.0;
        const double p = monomial_derivatives(centroid, 0, 0, 0).dot(bcc_cubic_power_coefficients(solve, d));
        return face_coefficient_from_centroid(d, l, p);
    });
}

BccFaceWeights bcc_cubic_c0_face_weights() {
    return weights_from_rule([](const DataVector& d, int l) { return c0_face_coefficient(d, l); });
}

}  // namespace sdf
