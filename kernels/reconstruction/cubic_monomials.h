/// @file cubic_monomials.h
/// @brief The 20 monomials x^a y^b z^c, a+b+c <= 3, that span the trivariate cubics (thesis
/// section 4.1.1, the vector m of eq. 4-6), and a cubic in that power basis evaluated with
/// its gradient and Hessian. Shared by the 27-point least-squares fit (eqs. 4-12..4-14) and
/// the host-side solve of eq. 4-9, so both use one monomial order.
#pragma once

#include "kernels/core/vec3.h"

namespace sdf {

constexpr int kCubicMonomials = 20;

/// Exponents (a, b, c) of monomial n, ordered by degree: 1, x, y, z, x^2, xy, xz, y^2, yz,
/// z^2, x^3, x^2y, x^2z, xy^2, xyz, xz^2, y^3, y^2z, yz^2, z^3.
SDF_CPU_GPU inline Int3 cubic_monomial_exponents(int n) {
    constexpr int table[kCubicMonomials][3] = {
        {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 0}, {1, 1, 0}, {1, 0, 1},
        {0, 2, 0}, {0, 1, 1}, {0, 0, 2}, {3, 0, 0}, {2, 1, 0}, {2, 0, 1}, {1, 2, 0},
        {1, 1, 1}, {1, 0, 2}, {0, 3, 0}, {0, 2, 1}, {0, 1, 2}, {0, 0, 3},
    };
    return {table[n][0], table[n][1], table[n][2]};
}

/// Index of the monomial with exponents (a, b, c), or -1 if a+b+c > 3.
SDF_CPU_GPU inline int cubic_monomial_index(int a, int b, int c) {
    for (int n = 0; n < kCubicMonomials; ++n) {
        const Int3 e = cubic_monomial_exponents(n);
        if (e.x == a && e.y == b && e.z == c) return n;
    }
    return -1;
}

/// Second derivatives, mixed first (the ones thesis eq. 4-3 constrains).
template <typename T>
struct SymmetricHessian {
    T xy{}, xz{}, yz{}, xx{}, yy{}, zz{};
};

template <typename T>
struct CubicJet {
    T value{};
    Vec3<T> gradient{};
    SymmetricHessian<T> hessian{};
};

/// d^k/dt^k t^e (k = 0, 1, 2), for e <= 3.
template <typename T>
SDF_CPU_GPU T monomial_derivative_1d(T t, int e, int k) {
    T r = T(1);
    for (int i = 0; i < k; ++i) r *= T(e - i);
    for (int i = 0; i < e - k; ++i) r *= t;
    return e < k ? T(0) : r;
}

/// Value, gradient and Hessian of sum_n a[n] * m_n(x).
template <typename T>
SDF_CPU_GPU CubicJet<T> evaluate_power_cubic(const T* a, const Vec3<T>& x) {
    CubicJet<T> j;
    for (int n = 0; n < kCubicMonomials; ++n) {
        const Int3 e = cubic_monomial_exponents(n);
        T d[3][3];  // d[axis][k] = k-th derivative of the axis factor
        for (int axis = 0; axis < 3; ++axis)
            for (int k = 0; k < 3; ++k) d[axis][k] = monomial_derivative_1d(x[axis], e[axis], k);
        j.value += a[n] * d[0][0] * d[1][0] * d[2][0];
        j.gradient.x += a[n] * d[0][1] * d[1][0] * d[2][0];
        j.gradient.y += a[n] * d[0][0] * d[1][1] * d[2][0];
        j.gradient.z += a[n] * d[0][0] * d[1][0] * d[2][1];
        j.hessian.xy += a[n] * d[0][1] * d[1][1] * d[2][0];
        j.hessian.xz += a[n] * d[0][1] * d[1][0] * d[2][1];
        j.hessian.yz += a[n] * d[0][0] * d[1][1] * d[2][1];
        j.hessian.xx += a[n] * d[0][2] * d[1][0] * d[2][0];
        j.hessian.yy += a[n] * d[0][0] * d[1][2] * d[2][0];
        j.hessian.zz += a[n] * d[0][0] * d[1][0] * d[2][2];
    }
    return j;
}

}  // namespace sdf
