/// @file bcc_cubic_tables.h
/// @brief Host-side construction of the BCC cubic's face-centre weights on the reference
/// tetrahedron (kernels/reconstruction/bcc_tetrahedron.h), solved once with Eigen.
///
/// bcc_cubic (thesis eqs. 4-3 to 4-9): in the power basis m of the 20 cubic monomials, the
/// 16 interpolation constraints are M a = f (eq. 4-5, M is 16 x 20), the objective is
/// a^T G a + h^T a + b (eq. 4-4) with G and h of eq. 4-7, a = a0 + Z t with a0 = M^+ f and Z a
/// null-space basis of M, and t solves (Z^T G Z) t = -Z^T (h/2 + G a0) (eq. 4-9). The result
/// is linear in the data: a = A_f f + A_s s, s = the 12 mixed second derivatives.
/// The face-centre Bernstein-Bezier coefficient of face l then follows from p at the face
/// centroid: c_F = (27 p(centroid) - sum_i f_i - 3 sum_{i != j} c_ij) / 6 over the face.
///
/// bcc_cubic_c0 (kernels/reconstruction/bcc_cubic_c0.h): c_F minimises the squared
/// Frobenius error of the tangential Hessian at the face's vertices.
///
/// Data order of a weight row: 10 per vertex (BccDatum: f, fx, fy, fz, fxy, fxz, fyz, fxx,
/// fyy, fzz), vertex-major: column 10 v + k.
#pragma once

#include <Eigen/Dense>

#include "kernels/reconstruction/lattice_field_view.h"

namespace sdf {

constexpr int kBccTableColumns = 4 * kBccData;
using BccFaceWeights = Eigen::Matrix<double, 4, kBccTableColumns>;

/// The pieces of eqs. 4-5 to 4-9 on the reference tetrahedron (coordinates in h/2).
struct BccCubicReferenceSolve {
    Eigen::Matrix<double, 16, 20> M;   ///< rows 4v + (value, d/dx, d/dy, d/dz) at vertex v
    Eigen::Matrix<double, 20, 20> G;   ///< eq. 4-7
    Eigen::Matrix<double, 20, 12> N;   ///< h = -2 N s; columns 3v + (xy, xz, yz)
    Eigen::Matrix<double, 20, 4> Z;    ///< null-space basis of M
    Eigen::Matrix<double, 20, 16> Af;  ///< a = Af f + As s
    Eigen::Matrix<double, 20, 12> As;
    double min_eigenvalue_ZGZ = 0;     ///< > 0: the minimiser of eq. 4-9 is unique
};

BccCubicReferenceSolve solve_bcc_cubic_reference();

/// Power-basis coefficients (reference frame) of bcc_cubic for vertex data in table order.
Eigen::Matrix<double, 20, 1> bcc_cubic_power_coefficients(const BccCubicReferenceSolve& solve,
                                                          const Eigen::Matrix<double, kBccTableColumns, 1>& data);

BccFaceWeights bcc_cubic_face_weights();     ///< eq. 4-9 (faithful)
BccFaceWeights bcc_cubic_c0_face_weights();  ///< face-local tangential-Hessian fit

template <typename T>
BccFaceTable<T> to_face_table(const BccFaceWeights& w) {
    BccFaceTable<T> t;
    for (int l = 0; l < 4; ++l)
        for (int v = 0; v < 4; ++v)
            for (int k = 0; k < kBccData; ++k) t.w[v][k][l] = T(w(l, kBccData * v + k));
    return t;
}

}  // namespace sdf
