// Lekien-Marsden tricubic interpolation (thesis 4.2): the 64x64 matrix, built here from
// first principles with Eigen, has det 1 and an integer inverse equal to the kernel's
// Kronecker-product entries; the literal matrix path and the factored evaluate() agree; and
// every tricubic is reproduced from exact Hermite data.
#include <gtest/gtest.h>

#include <cmath>

#include "core/reconstruction/lekien_marsden_matrix.h"
#include "kernels/reconstruction/tricubic_lekien_marsden.h"
#include "reconstruction_test_util.h"

namespace sdf {
namespace {

TEST(LekienMarsden, ConstraintMatrixHasUnitDeterminantAndTheKernelsIntegerInverse) {
    const LekienMarsdenMatrix b = lekien_marsden_constraint_matrix();
    EXPECT_NEAR(std::abs(b.determinant()), 1.0, 1e-9);  // thesis: "a determinant of 1"
    const LekienMarsdenMatrix inv = b.inverse();
    int nonzeros = 0;
    for (int r = 0; r < 64; ++r)
        for (int c = 0; c < 64; ++c) {
            EXPECT_NEAR(inv(r, c), double(lekien_marsden_matrix_entry(r, c)), 1e-9) << r << "," << c;
            nonzeros += lekien_marsden_matrix_entry(r, c) != 0;
        }
    EXPECT_EQ(nonzeros, 1000);  // 10 nonzeros of the 4x4 Hermite matrix, cubed
}

TEST(LekienMarsden, ReproducesEveryTricubicFromExactHermiteData) {
    std::mt19937 rng(21);
    const Lattice l = test::make_lattice(LatticeType::CC, {5, 4, 6}, 0.3);
    for (int trial = 0; trial < 5; ++trial) {
        const TricubicPolynomial<double> p = test::random_tricubic(rng);
        const HermiteData<double> d = test::exact_hermite_data(l, kind_of<TricubicLekienMarsden>(), p);
        const LatticeFieldView<double> v = d.view();
        for (const Vec3d& x : test::random_points(rng, TricubicLekienMarsden::domain(v), 200)) {
            const ReconstructedSample<double> got = TricubicLekienMarsden::evaluate(v, x);
            const AnalyticSample<double> want = p(x);
            const double scale = 1 + std::abs(want.value);
            EXPECT_NEAR(got.value, want.value, 1e-10 * scale);
            EXPECT_LT(length(got.gradient - want.gradient), 1e-9 * (1 + length(want.gradient)));
        }
    }
}

TEST(LekienMarsden, MatrixPathEqualsFactoredEvaluation) {
    std::mt19937 rng(22);
    const Lattice l = test::make_lattice(LatticeType::CC, {4, 4, 4}, 0.5);
    HermiteData<double> d = test::exact_hermite_data(l, kind_of<TricubicLekienMarsden>(), TrigFunction<double>{2.0});
    const LatticeFieldView<double> v = d.view();
    for (const Vec3d& x : test::random_points(rng, TricubicLekienMarsden::domain(v), 100)) {
        const CcCell<double> cell = cc_cell_at(v, x);
        double b[64], a[64];
        lekien_marsden_cell_data(v, cell.corner, b);
        lekien_marsden_coefficients(b, a);
        const ReconstructedSample<double> literal = evaluate_tricubic_power(a, cell.t);
        const ReconstructedSample<double> factored = TricubicLekienMarsden::evaluate(v, x);
        EXPECT_NEAR(literal.value, factored.value, 1e-12);
        EXPECT_LT(length(literal.gradient * v.inv_unit - factored.gradient), 1e-11);
    }
}

}  // namespace
}  // namespace sdf
