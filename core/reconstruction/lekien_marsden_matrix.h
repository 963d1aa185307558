/// @file lekien_marsden_matrix.h
/// @brief The 64x64 constraint matrix B of Lekien & Marsden's tricubic interpolation (thesis
/// section 4.2), built from first principles with Eigen: row 8 * type + corner holds the
/// datum `type` (f, fx, fy, fz, fxy, fxz, fyz, fxyz) of every monomial x^i y^j z^k (column
/// i + 4j + 16k) at the unit cube's corner (cx + 2cy + 4cz). The tests check det B = 1 and
/// that B^-1 is the integer matrix the kernel uses (tricubic_lekien_marsden.h).
#pragma once

#include <Eigen/Dense>

namespace sdf {

using LekienMarsdenMatrix = Eigen::Matrix<double, 64, 64>;

LekienMarsdenMatrix lekien_marsden_constraint_matrix();

}  // namespace sdf
