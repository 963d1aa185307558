// The BCC box splines as functions: the explicit forms (bcc_box_linear.h's closed form,
// bcc_box_quintic.h's generated Bezier table) against the box spline's definition integrated
// numerically (box_spline_test_util.h), at 10^4 random points each; symmetry under the 48
// signed axis permutations; values at the lattice points; partition of unity; analytic
// derivatives against differences of the explicit form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "box_spline_test_util.h"

namespace sdf {
namespace {

/// Uniform random points of the support |x_i| + |x_j| < radius (rejection from the cube).
std::vector<Vec3d> points_in_support(std::mt19937& rng, double radius, int n) {
    std::uniform_real_distribution<double> u(-radius, radius);
    std::vector<Vec3d> p;
    while (int(p.size()) < n) {
        const Vec3d x(u(rng), u(rng), u(rng));
        if (std::abs(x.x) + std::abs(x.y) < radius && std::abs(x.x) + std::abs(x.z) < radius &&
            std::abs(x.y) + std::abs(x.z) < radius)
            p.push_back(x);
    }
    return p;
}

TEST(BoxSplineKernels, LinearClosedFormEqualsTheConvolutionIntegral) {
    std::mt19937 rng(1);
    double worst = 0;
    for (const Vec3d& x : points_in_support(rng, 2.2, 10000))
        worst = std::max(worst, std::abs(bcc_box_linear_kernel(x) - test::phi4_by_integration(x)));
    std::printf("phi4: max |closed form - integral| over 10^4 points = %.3e\n", worst);
    EXPECT_LT(worst, 1e-14);
}

TEST(BoxSplineKernels, QuinticTableEqualsTheConvolutionIntegral) {
    // Acceptance of issue 17: 10^4 random points, 1e-12 in double. Alternate points put the
    // origin on a primary and on a secondary point, so every row of the table is used.
    std::mt19937 rng(2);
    double worst = 0, largest = 0;
    int n = 0;
    for (const Vec3d& x : points_in_support(rng, 4.2, 10000)) {
        const double explicit_form = bcc_box_quintic_kernel(x, ++n % 2 == 0).value;
        const double integral = test::phi8_by_integration(x);
        worst = std::max(worst, std::abs(explicit_form - integral));
        largest = std::max(largest, integral);
    }
    std::printf("phi8: max |explicit form - integral| over 10^4 points = %.3e (max phi8 seen %.4f)\n", worst, largest);
    EXPECT_LT(worst, 1e-12);
    EXPECT_GT(largest, 0.3);  // points near the centre were probed (phi8(0) = 0.4)
}

TEST(BoxSplineKernels, QuinticFilterEqualsTheSumOfIntegrals) {
    // The filter's own path (tetrahedron location, gather of 32 points through the symmetry,
    // Bezier net, de Casteljau) against sum_k c_k phi8(u - k) with phi8 integrated
    // numerically, random c, away from the mirror boundary.
    const Lattice l = test::make_lattice(LatticeType::BCC, {9, 9, 9}, 1.0, Vec3d(0.0));
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> u(-1, 1), inner(6, 10);
    HermiteData<double> d;
    d.lattice = l;
    for (int64_t i = 0; i < l.num_points(); ++i) d.values.push_back(u(rng));
    double worst = 0;
    for (int n = 0; n < 200; ++n) {
        const Vec3d p(inner(rng), inner(rng), inner(rng));  // lattice units = world / (h/2)
        double sum = 0;
        for (int64_t i = 0; i < l.num_points(); ++i) {
            const Int3 k = l.coords_of(i);
            const Vec3d x = p - Vec3d(k.x, k.y, k.z);
            if (std::abs(x.x) + std::abs(x.y) < 4 && std::abs(x.x) + std::abs(x.z) < 4 && std::abs(x.y) + std::abs(x.z) < 4)
                sum += d.values[size_t(i)] * test::phi8_by_integration(x);
        }
        worst = std::max(worst, std::abs(BccBoxQuinticApprox::evaluate(d.view(), d.view().to_world(p)).value - sum));
    }
    std::printf("s(u): max |filter - sum of integrals| over 200 points = %.3e\n", worst);
    EXPECT_LT(worst, 1e-12);
}

TEST(BoxSplineKernels, ValuesAtTheLatticePoints) {
    const double tol = 1e-15;
    EXPECT_NEAR(bcc_box_quintic_kernel(Vec3d(0.0)).value, 0.4, tol);
    EXPECT_NEAR(bcc_box_quintic_kernel(Vec3d(1.0, -1.0, 1.0)).value, 1.0 / 20, tol);
    EXPECT_NEAR(bcc_box_quintic_kernel(Vec3d(0.0, 0.0, -2.0)).value, 1.0 / 30, tol);
    for (const Vec3d& k : {Vec3d(2.0, 2.0, 0.0), Vec3d(3.0, 1.0, -1.0), Vec3d(4.0, 0.0, 0.0), Vec3d(2.0, 2.0, 2.0)}) {
        const SplineJet<double> j = bcc_box_quintic_kernel(k);
        EXPECT_NEAR(j.value, 0.0, tol) << k.x << " " << k.y << " " << k.z;
        EXPECT_LT(length(j.gradient), tol);  // C2: the support boundary is flat to second order
    }
    EXPECT_EQ(bcc_box_linear_kernel(Vec3d(0.0)), 1.0);
    for (const Vec3d& k : {Vec3d(1.0, 1.0, -1.0), Vec3d(2.0, 0.0, 0.0), Vec3d(2.0, 2.0, 0.0)})
        EXPECT_EQ(bcc_box_linear_kernel(k), 0.0);
}

TEST(BoxSplineKernels, InvariantUnderTheCubicGroup) {
    std::mt19937 rng(3);
    const auto group = test::cubic_group();
    ASSERT_EQ(group.size(), 48u);
    double worst = 0, worst_gradient = 0;
    int n = 0;
    for (const Vec3d& x : points_in_support(rng, 4.0, 500)) {
        const bool odd = ++n % 2 == 0;
        const SplineJet<double> a = bcc_box_quintic_kernel(x, odd);
        for (const auto& g : group) {
            const SplineJet<double> b = bcc_box_quintic_kernel(g.apply(x), !odd);
            worst = std::max(worst, std::abs(a.value - b.value));
            worst_gradient = std::max(worst_gradient, length(g.apply(a.gradient) - b.gradient));
        }
    }
    std::printf("phi8(g x) - phi8(x) over 48 g x 500 points: value %.2e, gradient %.2e\n", worst, worst_gradient);
    EXPECT_LT(worst, 1e-15);
    EXPECT_LT(worst_gradient, 1e-14);
}

TEST(BoxSplineKernels, PartitionOfUnity) {
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-1, 1);
    double worst = 0, worst_linear = 0, worst_gradient = 0;
    for (int n = 0; n < 300; ++n) {
        const Vec3d x(u(rng), u(rng), u(rng));
        double sum = 0, sum_linear = 0;
        Vec3d gradient(0.0);
        for (int i = -6; i <= 6; ++i)
            for (int j = -6; j <= 6; ++j)
                for (int k = -6; k <= 6; ++k) {
                    if ((i & 1) != (j & 1) || (j & 1) != (k & 1)) continue;  // BCC: all even or all odd
                    const SplineJet<double> s = bcc_box_quintic_kernel(x - Vec3d(i, j, k), n % 2 == 1);
                    sum += s.value;
                    gradient += s.gradient;
                    sum_linear += bcc_box_linear_kernel(x - Vec3d(i, j, k));
                }
        worst = std::max(worst, std::abs(sum - 1));
        worst_linear = std::max(worst_linear, std::abs(sum_linear - 1));
        worst_gradient = std::max(worst_gradient, length(gradient));
    }
    EXPECT_LT(worst, 1e-14);
    EXPECT_LT(worst_gradient, 1e-14);
    EXPECT_LT(worst_linear, 1e-15);
}

TEST(BoxSplineKernels, DerivativesAreTheExplicitFormsDerivatives) {
    std::mt19937 rng(5);
    const double e = 1e-5;
    double worst_gradient = 0, worst_hessian = 0;
    int n = 0;
    for (const Vec3d& x : points_in_support(rng, 4.0, 2000)) {
        const bool odd = ++n % 2 == 0;
        const SplineJet<double> s = bcc_box_quintic_kernel(x, odd);
        for (int a = 0; a < 3; ++a) {
            Vec3d step(0.0);
            step[a] = e;
            const SplineJet<double> hi = bcc_box_quintic_kernel(x + step, odd), lo = bcc_box_quintic_kernel(x - step, odd);
            worst_gradient = std::max(worst_gradient, std::abs((hi.value - lo.value) / (2 * e) - s.gradient[a]));
            for (int b = 0; b < 3; ++b)
                worst_hessian = std::max(worst_hessian, std::abs((hi.gradient[b] - lo.gradient[b]) / (2 * e) -
                                                                 hessian_entry(s.hessian, a, b)));
        }
    }
    // Differences across a knot plane are exact for C2 (gradient) and C1-of-the-gradient
    // pieces only to O(e): the Hessian tolerance covers the third-derivative jumps.
    EXPECT_LT(worst_gradient, 1e-9);
    EXPECT_LT(worst_hessian, 1e-4);
}

}  // namespace
}  // namespace sdf
