/// @file analytic_functions.h
/// @brief Analytic test functions with exact derivatives, for tests and experiments: a
/// general trivariate cubic, a tricubic (degree <= 3 per axis), a smooth non-separable
/// trigonometric function, and the Marschner-Lobb function.
///
/// Marschner & Lobb, "An evaluation of reconstruction filters for volume rendering" (IEEE
/// Visualization 1994): on [-1,1]^3,
///   rho(x,y,z) = (1 - sin(pi z / 2) + alpha (1 + rho_r(sqrt(x^2 + y^2)))) / (2 (1 + alpha)),
///   rho_r(r)   = cos(2 pi f_M cos(pi r / 2)),  with f_M = 6, alpha = 0.25 (thesis Table 4-1).
/// Each function returns an AnalyticSample; the derivatives are written out by hand here,
/// independently of the reconstruction code they are used to check.
#pragma once

#include <cmath>

#include "kernels/reconstruction/cubic_monomials.h"

namespace sdf {

template <typename T>
struct AnalyticSample {
    T value{};
    Vec3<T> gradient{};
    SymmetricHessian<T> hessian{};
    T dxyz{};  ///< third mixed derivative, the last Lekien-Marsden datum
};

/// p = sum c[n] m_n with the monomial order of cubic_monomials.h:
/// 1, x, y, z, x^2, xy, xz, y^2, yz, z^2, x^3, x^2y, x^2z, xy^2, xyz, xz^2, y^3, y^2z, yz^2, z^3.
template <typename T>
struct CubicPolynomial {
    T c[20]{};

    SDF_CPU_GPU AnalyticSample<T> operator()(const Vec3<T>& p) const {
        const T x = p.x, y = p.y, z = p.z;
        AnalyticSample<T> s;
        s.value = c[0] + c[1] * x + c[2] * y + c[3] * z + c[4] * x * x + c[5] * x * y + c[6] * x * z +
                  c[7] * y * y + c[8] * y * z + c[9] * z * z + c[10] * x * x * x + c[11] * x * x * y +
                  c[12] * x * x * z + c[13] * x * y * y + c[14] * x * y * z + c[15] * x * z * z +
                  c[16] * y * y * y + c[17] * y * y * z + c[18] * y * z * z + c[19] * z * z * z;
        s.gradient.x = c[1] + 2 * c[4] * x + c[5] * y + c[6] * z + 3 * c[10] * x * x + 2 * c[11] * x * y +
                       2 * c[12] * x * z + c[13] * y * y + c[14] * y * z + c[15] * z * z;
        s.gradient.y = c[2] + c[5] * x + 2 * c[7] * y + c[8] * z + c[11] * x * x + 2 * c[13] * x * y +
                       c[14] * x * z + 3 * c[16] * y * y + 2 * c[17] * y * z + c[18] * z * z;
        s.gradient.z = c[3] + c[6] * x + c[8] * y + 2 * c[9] * z + c[12] * x * x + c[14] * x * y +
                       2 * c[15] * x * z + c[17] * y * y + 2 * c[18] * y * z + 3 * c[19] * z * z;
        s.hessian.xx = 2 * c[4] + 6 * c[10] * x + 2 * c[11] * y + 2 * c[12] * z;
        s.hessian.yy = 2 * c[7] + 2 * c[13] * x + 6 * c[16] * y + 2 * c[17] * z;
        s.hessian.zz = 2 * c[9] + 2 * c[15] * x + 2 * c[18] * y + 6 * c[19] * z;
        s.hessian.xy = c[5] + 2 * c[11] * x + 2 * c[13] * y + c[14] * z;
        s.hessian.xz = c[6] + 2 * c[12] * x + c[14] * y + 2 * c[15] * z;
        s.hessian.yz = c[8] + c[14] * x + 2 * c[17] * y + 2 * c[18] * z;
        s.dxyz = c[14];
        return s;
    }
};

/// p = sum c[i][j][k] x^i y^j z^k, i, j, k <= 3 (reproduced exactly by tricubic_lm).
template <typename T>
struct TricubicPolynomial {
    T c[4][4][4]{};

    SDF_CPU_GPU AnalyticSample<T> operator()(const Vec3<T>& p) const {
        T px[3][4], py[3][4], pz[3][4];  // [derivative order][exponent]
        powers(p.x, px);
        powers(p.y, py);
        powers(p.z, pz);
        AnalyticSample<T> s;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                for (int k = 0; k < 4; ++k) {
                    const T a = c[i][j][k];
                    s.value += a * px[0][i] * py[0][j] * pz[0][k];
                    s.gradient.x += a * px[1][i] * py[0][j] * pz[0][k];
                    s.gradient.y += a * px[0][i] * py[1][j] * pz[0][k];
                    s.gradient.z += a * px[0][i] * py[0][j] * pz[1][k];
                    s.hessian.xy += a * px[1][i] * py[1][j] * pz[0][k];
                    s.hessian.xz += a * px[1][i] * py[0][j] * pz[1][k];
                    s.hessian.yz += a * px[0][i] * py[1][j] * pz[1][k];
                    s.hessian.xx += a * px[2][i] * py[0][j] * pz[0][k];
                    s.hessian.yy += a * px[0][i] * py[2][j] * pz[0][k];
                    s.hessian.zz += a * px[0][i] * py[0][j] * pz[2][k];
                    s.dxyz += a * px[1][i] * py[1][j] * pz[1][k];
                }
        return s;
    }

    /// t^e, d/dt t^e and d2/dt2 t^e for e = 0..3.
    SDF_CPU_GPU static void powers(T t, T out[3][4]) {
        out[0][0] = 1; out[0][1] = t; out[0][2] = t * t; out[0][3] = t * t * t;
        out[1][0] = 0; out[1][1] = 1; out[1][2] = 2 * t; out[1][3] = 3 * t * t;
        out[2][0] = 0; out[2][1] = 0; out[2][2] = 2;     out[2][3] = 6 * t;
    }
};

/// f = sin(k1 . p + phi1) + 0.5 cos(k2 . p + phi2): smooth, non-separable, not a polynomial.
/// `scale` multiplies both wave vectors (higher = harder to reconstruct).
template <typename T>
struct TrigFunction {
    T scale{1};

    SDF_CPU_GPU AnalyticSample<T> operator()(const Vec3<T>& p) const {
        const Vec3<T> k1 = Vec3<T>(T(1.3), T(-0.7), T(2.1)) * scale;
        const Vec3<T> k2 = Vec3<T>(T(-1.9), T(1.1), T(0.8)) * scale;
        const T a = dot(k1, p) + T(0.4), b = dot(k2, p) - T(0.3);
        const T sa = std::sin(a), ca = std::cos(a), sb = std::sin(b), cb = std::cos(b);
        AnalyticSample<T> s;
        s.value = sa + T(0.5) * cb;
        s.gradient = k1 * ca - k2 * (T(0.5) * sb);
        // Hessian: -sin(a) k1 k1^T - 0.5 cos(b) k2 k2^T
        auto second = [&](int i, int j) { return -sa * k1[i] * k1[j] - T(0.5) * cb * k2[i] * k2[j]; };
        s.hessian = {second(0, 1), second(0, 2), second(1, 2), second(0, 0), second(1, 1), second(2, 2)};
        s.dxyz = -ca * k1.x * k1.y * k1.z + T(0.5) * sb * k2.x * k2.y * k2.z;
        return s;
    }
};

/// The Marschner-Lobb function (value and gradient; the Hessian is not provided).
template <typename T>
struct MarschnerLobb {
    T f_m{6};
    T alpha{T(0.25)};

    SDF_CPU_GPU AnalyticSample<T> operator()(const Vec3<T>& p) const {
        const T pi = T(3.14159265358979323846);
        const T norm = T(1) / (T(2) * (T(1) + alpha));
        const T r = std::sqrt(p.x * p.x + p.y * p.y);
        const T phase = T(2) * pi * f_m * std::cos(pi * r / T(2));
        AnalyticSample<T> s;
        s.value = (T(1) - std::sin(pi * p.z / T(2)) + alpha * (T(1) + std::cos(phase))) * norm;
        // d rho_r / dr = pi^2 f_M sin(phase) sin(pi r / 2); divided by r, with its r -> 0 limit.
        const T drho_over_r = r > T(1e-6) ? pi * pi * f_m * std::sin(phase) * std::sin(pi * r / T(2)) / r
                                          : pi * pi * f_m * std::sin(phase) * pi / T(2);
        s.gradient.x = alpha * drho_over_r * p.x * norm;
        s.gradient.y = alpha * drho_over_r * p.y * norm;
        s.gradient.z = -pi / T(2) * std::cos(pi * p.z / T(2)) * norm;
        return s;
    }
};

}  // namespace sdf
