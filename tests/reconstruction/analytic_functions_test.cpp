// The analytic test functions' hand-written derivatives against central differences of
// their values (and gradients), and the Marschner-Lobb function's known values.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kernels/reconstruction/analytic_functions.h"
#include "reconstruction_test_util.h"

namespace sdf {
namespace {

/// Checks gradient (from values) and, when `hessian`, Hessian and dxyz (from gradients).
template <typename F>
void expect_consistent_derivatives(const F& f, const Vec3d& p, bool hessian, double tol) {
    const double e = 1e-5;
    const AnalyticSample<double> s = f(p);
    Vec3d g, gp[3], gm[3];
    for (int a = 0; a < 3; ++a) {
        Vec3d d(0.0);
        d[a] = e;
        g[a] = (f(p + d).value - f(p - d).value) / (2 * e);
        gp[a] = f(p + d).gradient;
        gm[a] = f(p - d).gradient;
    }
    EXPECT_LT(length(g - s.gradient), tol * (1 + length(s.gradient)));
    if (!hessian) return;
    auto h = [&](int a, int b) { return (gp[b][a] - gm[b][a]) / (2 * e); };  // d/db of df/da
    EXPECT_NEAR(s.hessian.xx, h(0, 0), tol * 10);
    EXPECT_NEAR(s.hessian.yy, h(1, 1), tol * 10);
    EXPECT_NEAR(s.hessian.zz, h(2, 2), tol * 10);
    EXPECT_NEAR(s.hessian.xy, h(0, 1), tol * 10);
    EXPECT_NEAR(s.hessian.xz, h(0, 2), tol * 10);
    EXPECT_NEAR(s.hessian.yz, h(1, 2), tol * 10);
    // dxyz = d/dz of fxy, from the Hessians at z +- e
    Vec3d dz(0.0, 0.0, e);
    EXPECT_NEAR(s.dxyz, (f(p + dz).hessian.xy - f(p - dz).hessian.xy) / (2 * e), tol * 10);
}

TEST(AnalyticFunctions, DerivativesMatchFiniteDifferences) {
    std::mt19937 rng(71);
    std::uniform_real_distribution<double> u(-0.9, 0.9);
    const CubicPolynomial<double> cubic = test::random_cubic(rng);
    const TricubicPolynomial<double> tricubic = test::random_tricubic(rng);
    for (int trial = 0; trial < 50; ++trial) {
        const Vec3d p(u(rng), u(rng), u(rng));
        expect_consistent_derivatives(cubic, p, true, 1e-7);
        expect_consistent_derivatives(tricubic, p, true, 1e-7);
        expect_consistent_derivatives(TrigFunction<double>{2.0}, p, true, 1e-7);
        expect_consistent_derivatives(MarschnerLobb<double>{}, p, false, 1e-6);
    }
    // The r -> 0 limit of the Marschner-Lobb gradient
    expect_consistent_derivatives(MarschnerLobb<double>{}, Vec3d(1e-8, -2e-8, 0.3), false, 1e-6);
}

TEST(AnalyticFunctions, MarschnerLobbValues) {
    const MarschnerLobb<double> ml;  // f_M = 6, alpha = 0.25
    // rho(0,0,0) = (1 + alpha (1 + cos(2 pi f_M))) / (2 (1 + alpha)) = 1.5 / 2.5
    EXPECT_NEAR(ml(Vec3d(0.0)).value, 0.6, 1e-15);
    // z = 1, r = 1: (1 - 1 + alpha (1 + cos(0))) / 2.5 = 0.2
    EXPECT_NEAR(ml(Vec3d(1.0, 0.0, 1.0)).value, 0.2, 1e-15);
    std::mt19937 rng(72);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int i = 0; i < 1000; ++i) {
        const double v = ml(Vec3d(u(rng), u(rng), u(rng))).value;
        EXPECT_GE(v, 0.0);
        EXPECT_LE(v, 1.0);
    }
}

}  // namespace
}  // namespace sdf
