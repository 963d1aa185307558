/// @file tricubic_lekien_marsden.h
/// @brief Local tricubic interpolation with Hermite data on the CC lattice: Lekien &
/// Marsden, "Tricubic interpolation in three dimensions", IJNME 63 (2005); thesis 4.2.
///
/// Per cell, p(x,y,z) = sum_{i,j,k<=3} a_ijk x^i y^j z^k matches (f, fx, fy, fz, fxy, fxz,
/// fyz, fxyz) at the 8 corners: 64 constraints B a = b, and a = B^-1 b with the integer
/// 64x64 matrix of the paper (det B = 1). B^-1 is the Kronecker product of three copies of
/// the 1-D cubic Hermite matrix A (lekien_marsden_matrix_entry), so the interpolant is the
/// tensor-product cubic Hermite spline: C1, reproduces every tricubic, order 4 with exact
/// data. evaluate() uses that factored form (~250 multiply-adds instead of 4096);
/// lekien_marsden_coefficients() is the literal matrix product, kept for the tests.
///
/// The data are LatticeFieldView::first (per unit h) and ::higher (kCcDxy, kCcDxz, kCcDyz,
/// kCcDxyz), built by cc_finite_differences.h from true gradients or from values.
#pragma once

#include "kernels/reconstruction/cc_cell.h"

namespace sdf {

/// The 1-D cubic Hermite matrix: coefficient n of t^n from the data u = (f(0), f(1), f'(0),
/// f'(1)).
SDF_CPU_GPU constexpr int cubic_hermite_matrix(int n, int u) {
    constexpr int a[4][4] = {{1, 0, 0, 0}, {0, 0, 1, 0}, {-3, 3, -2, -1}, {2, -2, 1, 1}};
    return a[n][u];
}

/// Datum types in Lekien-Marsden order: f, fx, fy, fz, fxy, fxz, fyz, fxyz. Returns the
/// type index for derivative flags (dx, dy, dz).
SDF_CPU_GPU constexpr int lekien_marsden_type(int dx, int dy, int dz) {
    constexpr int type[8] = {0, 1, 2, 4, 3, 5, 6, 7};  // indexed by dx + 2 dy + 4 dz
    return type[dx + 2 * dy + 4 * dz];
}

/// Entry of B^-1: row = i + 4j + 16k (coefficient a_ijk), col = 8 * type + corner with
/// corner = cx + 2cy + 4cz (the b vector of the paper).
SDF_CPU_GPU constexpr int lekien_marsden_matrix_entry(int row, int col) {
    const int i = row % 4, j = (row / 4) % 4, k = row / 16;
    const int corner = col % 8, type = col / 8;
    int dx = 0, dy = 0, dz = 0;
    for (int d = 0; d < 8; ++d)
        if (lekien_marsden_type(d & 1, (d >> 1) & 1, d >> 2) == type) { dx = d & 1; dy = (d >> 1) & 1; dz = d >> 2; }
    return cubic_hermite_matrix(i, (corner & 1) + 2 * dx) * cubic_hermite_matrix(j, ((corner >> 1) & 1) + 2 * dy) *
           cubic_hermite_matrix(k, (corner >> 2) + 2 * dz);
}

/// The 8 Hermite data of one grid point, in Lekien-Marsden order.
template <typename T>
SDF_CPU_GPU void lekien_marsden_point_data(const LatticeFieldView<T>& v, int64_t index, T d[8]) {
    const Vec3<T> g = v.first[index];
    const T* h = v.higher + index * v.higher_stride;
    d[0] = v.values[index];
    d[1] = g.x; d[2] = g.y; d[3] = g.z;
    d[4] = h[kCcDxy]; d[5] = h[kCcDxz]; d[6] = h[kCcDyz]; d[7] = h[kCcDxyz];
}

/// The vector b of the paper for the cell with lower corner `c`: b[8 * type + corner].
template <typename T>
SDF_CPU_GPU void lekien_marsden_cell_data(const LatticeFieldView<T>& v, const Int3& c, T b[64]) {
    for (int corner = 0; corner < 8; ++corner) {
        T d[8];
        lekien_marsden_point_data(v, cc_index(v.lattice, c.x + (corner & 1), c.y + ((corner >> 1) & 1), c.z + (corner >> 2)), d);
        for (int type = 0; type < 8; ++type) b[8 * type + corner] = d[type];
    }
}

/// a = B^-1 b through the 64x64 matrix (the paper's formulation).
template <typename T>
SDF_CPU_GPU void lekien_marsden_coefficients(const T b[64], T a[64]) {
    for (int row = 0; row < 64; ++row) {
        T sum = T(0);
        for (int col = 0; col < 64; ++col) sum += T(lekien_marsden_matrix_entry(row, col)) * b[col];
        a[row] = sum;
    }
}

/// Value and gradient (per cell unit) of sum a_ijk x^i y^j z^k at t.
template <typename T>
SDF_CPU_GPU ReconstructedSample<T> evaluate_tricubic_power(const T a[64], const Vec3<T>& t) {
    T p[3][4], dp[3][4];
    for (int axis = 0; axis < 3; ++axis) {
        const T x = t[axis];
        p[axis][0] = 1; p[axis][1] = x; p[axis][2] = x * x; p[axis][3] = x * x * x;
        dp[axis][0] = 0; dp[axis][1] = 1; dp[axis][2] = 2 * x; dp[axis][3] = 3 * x * x;
    }
    ReconstructedSample<T> s;
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const T c = a[i + 4 * j + 16 * k];
                s.value += c * p[0][i] * p[1][j] * p[2][k];
                s.gradient += Vec3<T>(dp[0][i] * p[1][j] * p[2][k], p[0][i] * dp[1][j] * p[2][k],
                                      p[0][i] * p[1][j] * dp[2][k]) * c;
            }
    return s;
}

/// The 1-D Hermite basis H[u](t) = sum_n A[n][u] t^n and its derivative.
template <typename T>
SDF_CPU_GPU void cubic_hermite_basis(T t, T h[4], T dh[4]) {
    const T t2 = t * t, t3 = t2 * t;
    h[0] = 1 - 3 * t2 + 2 * t3;  dh[0] = 6 * t2 - 6 * t;
    h[1] = 3 * t2 - 2 * t3;      dh[1] = 6 * t - 6 * t2;
    h[2] = t - 2 * t2 + t3;      dh[2] = 1 - 4 * t + 3 * t2;
    h[3] = t3 - t2;              dh[3] = 3 * t2 - 2 * t;
}

struct TricubicLekienMarsden {
    SDF_CPU_GPU static constexpr const char* name() { return "tricubic_lm"; }
    SDF_CPU_GPU static constexpr int radius() { return 1; }
    SDF_CPU_GPU static constexpr int order() { return 4; }
    SDF_CPU_GPU static constexpr bool interpolating() { return true; }
    SDF_CPU_GPU static constexpr LatticeType lattice_type() { return LatticeType::CC; }
    SDF_CPU_GPU static constexpr bool uses_first() { return true; }
    SDF_CPU_GPU static constexpr int higher_stride() { return kCcHigherStride; }
    SDF_CPU_GPU static constexpr PointData point_data() { return PointData::CcTricubicJet; }
    SDF_CPU_GPU static constexpr int min_resolution() { return 3; }

    template <typename T>
    SDF_CPU_GPU static DomainBox<T> domain(const LatticeFieldView<T>& v) { return cc_domain(v); }

    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate(const LatticeFieldView<T>& v, const Vec3<T>& p) {
        const CcCell<T> cell = cc_cell_at(v, p);
        // g[ux][uy][uz], u = corner bit + 2 * derivative flag per axis: the Hermite data as a
        // 4x4x4 tensor, contracted with the 1-D bases one axis at a time
        T g[4][4][4];
        for (int corner = 0; corner < 8; ++corner) {
            const int cx = corner & 1, cy = (corner >> 1) & 1, cz = corner >> 2;
            T d[8];
            lekien_marsden_point_data(v, cc_index(v.lattice, cell.corner.x + cx, cell.corner.y + cy, cell.corner.z + cz), d);
            for (int flags = 0; flags < 8; ++flags)
                g[cx + 2 * (flags & 1)][cy + (flags & 2)][cz + ((flags >> 1) & 2)] =
                    d[lekien_marsden_type(flags & 1, (flags >> 1) & 1, flags >> 2)];
        }
        T h[3][4], dh[3][4];
        for (int axis = 0; axis < 3; ++axis) cubic_hermite_basis(cell.t[axis], h[axis], dh[axis]);
        // Contract x (value and d/dx), then y, then z
        T gx[4][4], gdx[4][4];
        for (int uy = 0; uy < 4; ++uy)
            for (int uz = 0; uz < 4; ++uz) {
                T s = 0, ds = 0;
                for (int ux = 0; ux < 4; ++ux) {
                    s += h[0][ux] * g[ux][uy][uz];
                    ds += dh[0][ux] * g[ux][uy][uz];
                }
                gx[uy][uz] = s;
                gdx[uy][uz] = ds;
            }
        T value = 0, gradx = 0, grady = 0, gradz = 0;
        for (int uz = 0; uz < 4; ++uz) {
            T s = 0, sdx = 0, sdy = 0;
            for (int uy = 0; uy < 4; ++uy) {
                s += h[1][uy] * gx[uy][uz];
                sdx += h[1][uy] * gdx[uy][uz];
                sdy += dh[1][uy] * gx[uy][uz];
            }
            value += h[2][uz] * s;
            gradx += h[2][uz] * sdx;
            grady += h[2][uz] * sdy;
            gradz += dh[2][uz] * s;
        }
        return {value, Vec3<T>(gradx, grady, gradz) * v.inv_unit, cell.inside};
    }
};

}  // namespace sdf
