// The 27-point least-squares derivative stencils of thesis section 4.1.3 (eqs. 4-12..4-15,
// Figure 4-2): exact for every cubic, integer weights in 1/24 (fx) and 1/72 (fyz), and the
// weighting changes only the even (second-derivative) stencils.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/reconstruction/bcc_least_squares.h"
#include "reconstruction_test_util.h"

namespace sdf {
namespace {

const StencilWeighting kPlain{};
const StencilWeighting kGaussLattice{true, 0.5, SigmaUnits::LatticeUnits};
const StencilWeighting kGaussSpacing{true, 0.5, SigmaUnits::Spacing};

/// Exact derivatives at the origin of a polynomial sampled at the 27 integer offsets.
void expect_fit_exact(const StencilWeighting& w, const CubicPolynomial<double>& p) {
    const BccFitMatrix k = bcc_least_squares_matrix(w);
    Eigen::Matrix<double, 27, 1> y;
    for (int n = 0; n < 27; ++n) {
        const Int3 o = bcc_neighbour_offset(n);
        y(n) = p(Vec3d(o.x, o.y, o.z)).value;
    }
    const Eigen::Matrix<double, 20, 1> a = k * y;
    const AnalyticSample<double> want = p(Vec3d(0.0));
    const CubicJet<double> got = evaluate_power_cubic(a.data(), Vec3d(0.0));
    const double tol = 1e-11;
    EXPECT_NEAR(got.value, want.value, tol);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(got.gradient[i], want.gradient[i], tol);
    EXPECT_NEAR(got.hessian.xy, want.hessian.xy, tol);
    EXPECT_NEAR(got.hessian.xz, want.hessian.xz, tol);
    EXPECT_NEAR(got.hessian.yz, want.hessian.yz, tol);
    EXPECT_NEAR(got.hessian.xx, want.hessian.xx, tol);
    EXPECT_NEAR(got.hessian.yy, want.hessian.yy, tol);
    EXPECT_NEAR(got.hessian.zz, want.hessian.zz, tol);
    // The whole fit is the polynomial itself: check the third mixed derivative too
    EXPECT_NEAR(a(cubic_monomial_index(1, 1, 1)), want.dxyz, tol);
}

TEST(BccLeastSquares, ExactForEveryCubicMonomialAndRandomCubics) {
    std::mt19937 rng(7);
    for (const StencilWeighting& w : {kPlain, kGaussLattice, kGaussSpacing}) {
        for (int m = 0; m < 20; ++m) {
            CubicPolynomial<double> p;
            p.c[m] = 1.0;
            expect_fit_exact(w, p);
        }
        for (int trial = 0; trial < 5; ++trial) expect_fit_exact(w, test::random_cubic(rng));
    }
}

void print_stencil(const char* name, const Eigen::Matrix<double, 27, 1>& s, double scale) {
    std::printf("%s x %g over (centre, 8 diagonals, 6 axis, 12 face-diagonal neighbours):\n  ", name, scale);
    for (int n = 0; n < 27; ++n) std::printf("%g%s", s(n) * scale, n == 0 || n == 8 || n == 14 ? " | " : " ");
    std::printf("\n");
}

TEST(BccLeastSquares, FigureFourTwoWeightsAreIntegerMultiplesOfOneTwentyFourthAndOneSeventySecond) {
    const auto fx = bcc_derivative_stencil(kPlain, 1, 0, 0);
    const auto fyz = bcc_derivative_stencil(kPlain, 0, 1, 1);
    print_stencil("fx (plain)", fx, 24);
    print_stencil("fyz (plain)", fyz, 72);
    for (int n = 0; n < 27; ++n) {
        EXPECT_NEAR(fx(n) * 24, std::round(fx(n) * 24), 1e-10) << "neighbour " << n;
        EXPECT_NEAR(fyz(n) * 72, std::round(fyz(n) * 72), 1e-10) << "neighbour " << n;
    }
    // Not coarser denominators in disguise: some weight needs the full 24 / 72
    bool needs_24 = false, needs_72 = false;
    for (int n = 0; n < 27; ++n) {
        needs_24 |= std::fmod(std::abs(std::round(fx(n) * 24)), 2.0) == 1.0;
        needs_72 |= std::fmod(std::abs(std::round(fyz(n) * 72)), 2.0) == 1.0;
    }
    EXPECT_TRUE(needs_24);
    EXPECT_TRUE(needs_72);
}

TEST(BccLeastSquares, WeightingChangesOnlyTheSecondDerivativeStencils) {
    // 13 antipodal pairs, 13 odd monomials: the odd part interpolates, whatever the weights
    const int odd[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {3, 0, 0}, {1, 2, 0}};
    const int even[][3] = {{1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}};
    for (const StencilWeighting& w : {kGaussLattice, kGaussSpacing}) {
        for (const auto& d : odd) {
            const double diff = (bcc_derivative_stencil(w, d[0], d[1], d[2]) - bcc_derivative_stencil(kPlain, d[0], d[1], d[2]))
                                    .cwiseAbs().maxCoeff();
            EXPECT_LT(diff, 1e-12) << "odd derivative " << d[0] << d[1] << d[2];
        }
        for (const auto& d : even) {
            const double diff = (bcc_derivative_stencil(w, d[0], d[1], d[2]) - bcc_derivative_stencil(kPlain, d[0], d[1], d[2]))
                                    .cwiseAbs().maxCoeff();
            EXPECT_GT(diff, 1e-3) << "even derivative " << d[0] << d[1] << d[2];
        }
    }
    print_stencil("fyz (sigma^2 = 0.5 lattice units)", bcc_derivative_stencil(kGaussLattice, 0, 1, 1), 72);
    print_stencil("fyz (sigma^2 = 0.5 h^2)", bcc_derivative_stencil(kGaussSpacing, 0, 1, 1), 72);
    print_stencil("fxx (plain)", bcc_derivative_stencil(kPlain, 2, 0, 0), 72);
}

TEST(BccLeastSquares, SigmaUnits) {
    EXPECT_DOUBLE_EQ(sigma2_in_lattice_units(kGaussLattice), 0.5);
    EXPECT_DOUBLE_EQ(sigma2_in_lattice_units(kGaussSpacing), 2.0);  // 0.5 h^2 = 2 (h/2)^2
    EXPECT_DOUBLE_EQ(stencil_weight(kGaussLattice, 0), 1.0);
    EXPECT_NEAR(stencil_weight(kGaussLattice, 1), std::exp(-3 / 0.5), 1e-15);  // diagonal, |x|^2 = 3
    EXPECT_NEAR(stencil_weight(kGaussSpacing, 9), std::exp(-4 / 2.0), 1e-15);  // axis, |x|^2 = 4
}

TEST(BccLeastSquares, EveryLatticePointIncludingTheBoundaryIsExactForCubics) {
    // Points near the boundary differentiate the nearest complete fit off-centre
    std::mt19937 rng(11);
    const CubicPolynomial<double> p = test::random_cubic(rng);
    const Lattice l = test::make_lattice(LatticeType::BCC, {4, 5, 6}, 0.4);
    const SampledField field = sample_analytic_field(l, p);
    const double u = l.half_spacing();
    for (const StencilWeighting& w : {kPlain, kGaussLattice}) {
        const std::vector<BccLeastSquaresFit<double>> fits = bcc_least_squares_fits<double>(w);
        double worst = 0;
        for (int64_t i = 0; i < l.num_points(); ++i) {
            const CubicJet<double> jet = bcc_least_squares_jet(fits.data(), l, field.distance.data(), l.coords_of(i));
            const AnalyticSample<double> want = p(l.position(i));
            worst = std::max(worst, std::abs(jet.value - want.value));
            worst = std::max(worst, length(jet.gradient - want.gradient * u));
            worst = std::max(worst, std::abs(jet.hessian.xy - want.hessian.xy * u * u));
            worst = std::max(worst, std::abs(jet.hessian.yz - want.hessian.yz * u * u));
            worst = std::max(worst, std::abs(jet.hessian.zz - want.hessian.zz * u * u));
        }
        EXPECT_LT(worst, 1e-10);
    }
}

}  // namespace
}  // namespace sdf
