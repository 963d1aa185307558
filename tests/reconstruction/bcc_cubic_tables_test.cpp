// The BCC cubic's constrained least-squares solve (thesis eqs. 4-3..4-9) on the reference
// tetrahedron, and its Bernstein-Bezier form used by the kernels.
#include <gtest/gtest.h>

#include <cstdio>

#include "kernels/reconstruction/bcc_cubic.h"
#include "reconstruction_test_util.h"

namespace sdf {
namespace {

using DataVector = Eigen::Matrix<double, kBccTableColumns, 1>;

DataVector random_data(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    DataVector d;
    for (int i = 0; i < kBccTableColumns; ++i) d(i) = u(rng);
    return d;
}

/// Reference-frame data of a cubic at the reference vertices.
DataVector cubic_data(const CubicPolynomial<double>& p) {
    DataVector d;
    for (int v = 0; v < 4; ++v) {
        const AnalyticSample<double> s =
            p(Vec3d(bcc_reference_vertex(v, 0), bcc_reference_vertex(v, 1), bcc_reference_vertex(v, 2)));
        const double x[kBccData] = {s.value,      s.gradient.x, s.gradient.y, s.gradient.z, s.hessian.xy,
                                    s.hessian.xz, s.hessian.yz, s.hessian.xx, s.hessian.yy, s.hessian.zz};
        for (int k = 0; k < kBccData; ++k) d(kBccData * v + k) = x[k];
    }
    return d;
}

/// The kernel's Bernstein-Bezier evaluation with a given table.
ReconstructedSample<double> kernel_eval(const BccFaceWeights& w, const DataVector& d, const Vec3d& r) {
    double data[4][kBccData];
    for (int v = 0; v < 4; ++v)
        for (int k = 0; k < kBccData; ++k) data[v][k] = d(kBccData * v + k);
    return evaluate_bcc_cubic_net(bcc_cubic_net(data, to_face_table<double>(w)), r);
}

/// A random point of the reference tetrahedron.
Vec3d random_reference_point(std::mt19937& rng) {
    std::gamma_distribution<double> g(1.0);
    double b[4], sum = 0;
    for (double& x : b) sum += (x = g(rng));
    Vec3d r(0.0);
    for (int v = 0; v < 4; ++v)
        r += Vec3d(bcc_reference_vertex(v, 0), bcc_reference_vertex(v, 1), bcc_reference_vertex(v, 2)) * (b[v] / sum);
    return r;
}

/// E(a) of eq. 4-3 for coefficient vector a and the mixed second derivatives in d.
double objective(const BccCubicReferenceSolve& s, const Eigen::Matrix<double, 20, 1>& a, const DataVector& d) {
    double e = 0;
    for (int v = 0; v < 4; ++v)
        for (int m = 0; m < 3; ++m) {
            const double r = s.N.col(3 * v + m).dot(a) - d(kBccData * v + kDxy + m);
            e += r * r;
        }
    return e;
}

TEST(BccCubicTables, EquationFourNineIsWellPosed) {
    const BccCubicReferenceSolve s = solve_bcc_cubic_reference();
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(s.M);
    EXPECT_GT(svd.singularValues()(15), 1e-3);  // rank 16 (thesis: "M is full rank")
    EXPECT_LT((s.M * s.Z).norm(), 1e-12);
    std::printf("smallest eigenvalue of Z^T G Z: %.6g\n", s.min_eigenvalue_ZGZ);
    EXPECT_GT(s.min_eigenvalue_ZGZ, 1e-6);
}

TEST(BccCubicTables, SolutionInterpolatesAndMinimisesTheObjective) {
    const BccCubicReferenceSolve s = solve_bcc_cubic_reference();
    std::mt19937 rng(5);
    for (int trial = 0; trial < 20; ++trial) {
        const DataVector d = random_data(rng);
        const Eigen::Matrix<double, 20, 1> a = bcc_cubic_power_coefficients(s, d);
        for (int v = 0; v < 4; ++v)
            for (int k = 0; k < 4; ++k) EXPECT_NEAR((s.M.row(4 * v + k) * a)(0), d(kBccData * v + k), 1e-12);
        const double e0 = objective(s, a, d);
        std::normal_distribution<double> n(0, 0.1);
        for (int t = 0; t < 10; ++t) {
            const Eigen::Vector4d dt(n(rng), n(rng), n(rng), n(rng));
            EXPECT_GE(objective(s, a + s.Z * dt, d), e0 - 1e-12);
        }
    }
}

TEST(BccCubicTables, BernsteinBezierKernelMatchesThePowerBasisSolution) {
    const BccCubicReferenceSolve s = solve_bcc_cubic_reference();
    const BccFaceWeights w = bcc_cubic_face_weights();
    std::mt19937 rng(9);
    for (int trial = 0; trial < 50; ++trial) {
        const DataVector d = random_data(rng);
        const Eigen::Matrix<double, 20, 1> a = bcc_cubic_power_coefficients(s, d);
        const Vec3d r = random_reference_point(rng);
        const CubicJet<double> want = evaluate_power_cubic(a.data(), r);
        const ReconstructedSample<double> got = kernel_eval(w, d, r);
        EXPECT_NEAR(got.value, want.value, 1e-12);
        EXPECT_LT(length(got.gradient - want.gradient), 1e-12);
    }
}

TEST(BccCubicTables, BothVariantsReproduceCubics) {
    std::mt19937 rng(13);
    for (const BccFaceWeights& w : {bcc_cubic_face_weights(), bcc_cubic_c0_face_weights()})
        for (int trial = 0; trial < 20; ++trial) {
            const CubicPolynomial<double> p = test::random_cubic(rng);
            const DataVector d = cubic_data(p);
            const Vec3d r = random_reference_point(rng);
            const ReconstructedSample<double> got = kernel_eval(w, d, r);
            EXPECT_NEAR(got.value, p(r).value, 1e-12);
            EXPECT_LT(length(got.gradient - p(r).gradient), 1e-12);
        }
}

TEST(BccCubicTables, FaceCentresOfTheFaithfulSplineDependOnTheOppositeVertexButNotInTheC0Variant) {
    const BccFaceWeights faithful = bcc_cubic_face_weights(), c0 = bcc_cubic_c0_face_weights();
    for (int l = 0; l < 4; ++l) {
        const double opposite_faithful = faithful.block(l, kBccData * l, 1, kBccData).cwiseAbs().maxCoeff();
        const double opposite_c0 = c0.block(l, kBccData * l, 1, kBccData).cwiseAbs().maxCoeff();
        std::printf("face %d: largest weight on the opposite vertex: bcc_cubic %.6g, bcc_cubic_c0 %.3g\n", l,
                    opposite_faithful, opposite_c0);
        EXPECT_GT(opposite_faithful, 1e-3);
        EXPECT_EQ(opposite_c0, 0.0);
        // The faithful weights ignore pure second derivatives (eq. 4-3 has only mixed ones)
        for (int v = 0; v < 4; ++v)
            for (int k = kDxx; k <= kDzz; ++k) EXPECT_EQ(faithful(l, kBccData * v + k), 0.0);
    }
}

}  // namespace
}  // namespace sdf
