// The spline filters through their interpolator interface: bcc_box_linear,
// bcc_box_quintic (interpolation prefilter), bcc_box_quintic_qi (quasi-interpolation),
// bcc_box_quintic_approx (no prefilter) and cc_bspline3 (interpolation prefilter).
// Truth: the lattice values, random polynomials, bcc_linear (an independent implementation
// of the same linear spline), the lattice's symmetry group, and the double kernels for float.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "box_spline_test_util.h"

namespace sdf {
namespace {

template <typename I>
ReconstructedSample<double> eval(const HermiteData<double>& d, const Vec3d& p) {
    return I::evaluate(d.view(), p);
}

/// The lattice's box shrunk by `margin` lattice units (h/2 on BCC, h on CC) per side.
DomainBox<double> inner_box(const Lattice& l, double margin) {
    const double unit = l.type == LatticeType::CC ? l.spacing : l.half_spacing();
    const Vec3d m(margin * unit);
    return {l.domain_min() + m, l.domain_max() - m};
}

struct Worst {
    double value = 0, gradient = 0;
    void add(const ReconstructedSample<double>& got, const AnalyticSample<double>& want) {
        value = std::max(value, std::abs(got.value - want.value));
        gradient = std::max(gradient, length(got.gradient - want.gradient));
    }
};

template <typename I, typename F>
Worst worst_error(const HermiteData<double>& d, const F& f, const DomainBox<double>& box, unsigned seed, int n = 2000) {
    std::mt19937 rng(seed);
    Worst w;
    for (const Vec3d& p : test::random_points(rng, box, n)) w.add(eval<I>(d, p), f(p));
    return w;
}

template <typename I>
double worst_at_lattice_points(const HermiteData<double>& d) {
    const LatticeFieldView<double> v = d.view();
    const DomainBox<double> box = I::domain(v);
    double worst = 0;
    int checked = 0;
    for (int64_t i = 0; i < d.lattice.num_points(); ++i) {
        const Vec3d p = d.lattice.position(i);
        bool in = true;
        for (int a = 0; a < 3; ++a) in = in && p[a] >= box.lo[a] - 1e-12 && p[a] <= box.hi[a] + 1e-12;
        if (!in) continue;
        worst = std::max(worst, std::abs(I::evaluate(v, p).value - d.values[size_t(i)]));
        ++checked;
    }
    EXPECT_GT(checked, 100) << I::name();
    return worst;
}

const Lattice kBcc = test::make_lattice(LatticeType::BCC, {12, 11, 13}, 0.1);
const Lattice kCc = test::make_lattice(LatticeType::CC, {12, 11, 13}, 0.1);

TEST(BoxSplineFilters, InterpolatingFiltersReproduceTheLatticeValues) {
    const TrigFunction<double> f{8.0};  // rough at this spacing: interpolation must not rely on smoothness
    const double bl = worst_at_lattice_points<BccBoxLinear>(test::spline_data<BccBoxLinear>(kBcc, f));
    const double bq = worst_at_lattice_points<BccBoxQuintic>(test::spline_data<BccBoxQuintic>(kBcc, f));
    const double cb = worst_at_lattice_points<CcBspline3>(test::spline_data<CcBspline3>(kCc, f));
    std::printf("max |s(k) - f(k)| at the lattice points: bcc_box_linear %.2e, bcc_box_quintic %.2e, cc_bspline3 %.2e\n",
                bl, bq, cb);
    EXPECT_LT(bl, 1e-14);
    EXPECT_LT(bq, 1e-12);
    EXPECT_LT(cb, 1e-13);
    // The others approximate: at the lattice points they are off by O(h^2)
    const double qi = worst_at_lattice_points<BccBoxQuinticQi>(test::spline_data<BccBoxQuinticQi>(kBcc, f));
    const double ap = worst_at_lattice_points<BccBoxQuinticApprox>(test::spline_data<BccBoxQuinticApprox>(kBcc, f));
    EXPECT_GT(qi, 1e-3);
    EXPECT_GT(ap, 1e-3);
}

TEST(BoxSplineFilters, BccBoxLinearIsBccLinear) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double> values(size_t(kBcc.num_points()));
    for (double& x : values) x = u(rng);
    const HermiteData<double> d = test::spline_data_from_values<BccBoxLinear>(kBcc, values);
    double worst = 0, worst_gradient = 0;
    for (const Vec3d& p : test::random_points(rng, BccBoxLinear::domain(d.view()), 5000)) {
        const auto a = BccBoxLinear::evaluate(d.view(), p), b = BccLinear::evaluate(d.view(), p);
        worst = std::max(worst, std::abs(a.value - b.value));
        worst_gradient = std::max(worst_gradient, length(a.gradient - b.gradient));
    }
    EXPECT_LT(worst, 1e-14);
    EXPECT_LT(worst_gradient, 1e-12);
}

TEST(BoxSplineFilters, PolynomialReproduction) {
    std::mt19937 rng(12);
    // Linear: bcc_box_linear everywhere in its domain
    TricubicPolynomial<double> linear = test::random_tricubic(rng);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k)
                if (i + j + k > 1) linear.c[i][j][k] = 0;
    {
        const HermiteData<double> d = test::spline_data<BccBoxLinear>(kBcc, linear);
        const Worst w = worst_error<BccBoxLinear>(d, linear, BccBoxLinear::domain(d.view()), 13);
        EXPECT_LT(w.value, 1e-13);
        EXPECT_LT(w.gradient, 1e-12);
    }
    // Far enough from the mirror boundary that every coefficient used is an unmirrored one:
    // 6 units (the 32 points of a tetrahedron), 7 with the quasi-interpolation filter
    const DomainBox<double> interior = inner_box(kBcc, 7);
    {
        const HermiteData<double> d = test::spline_data<BccBoxQuinticApprox>(kBcc, linear);
        const Worst w = worst_error<BccBoxQuinticApprox>(d, linear, interior, 14);
        EXPECT_LT(w.value, 1e-13) << "approx, linear";
        EXPECT_LT(w.gradient, 1e-12) << "approx, linear";
    }
    {
        // x^2 comes out as x^2 + (2/3) (h/2)^2 = x^2 + h^2/6 (the second moment of phi8)
        TricubicPolynomial<double> square;
        square.c[2][0][0] = 1;
        const HermiteData<double> d = test::spline_data<BccBoxQuinticApprox>(kBcc, square);
        std::mt19937 r2(15);
        const double h = kBcc.spacing;
        double worst = 0;
        for (const Vec3d& p : test::random_points(r2, interior, 1000))
            worst = std::max(worst, std::abs(eval<BccBoxQuinticApprox>(d, p).value - (p.x * p.x + h * h / 6)));
        EXPECT_LT(worst, 1e-14) << "approx: x^2 -> x^2 + h^2/6";
    }
    for (int trial = 0; trial < 3; ++trial) {
        const CubicPolynomial<double> cubic = test::random_cubic(rng);
        const HermiteData<double> d = test::spline_data<BccBoxQuinticQi>(kBcc, cubic);
        const Worst w = worst_error<BccBoxQuinticQi>(d, cubic, interior, 16 + trial);
        EXPECT_LT(w.value, 1e-12) << "qi, cubic";
        EXPECT_LT(w.gradient, 1e-11) << "qi, cubic";
    }
}

TEST(BoxSplineFilters, InterpolationPrefiltersReproduceCubicsAwayFromTheBoundary) {
    // The mirror extension of a cubic is not a cubic; its effect on the IIR coefficients
    // decays geometrically into the interior: by 0.268 per sample for the cubic B-spline
    // (its pole sqrt 3 - 2; (1/0.268)^6 = 2700 from a margin of 6h to 12h), faster for the
    // quintic box spline.
    std::mt19937 rng(20);
    const CubicPolynomial<double> cubic = test::random_cubic(rng);
    const Lattice bcc = test::make_lattice(LatticeType::BCC, {34, 34, 34}, 1.0 / 33, Vec3d(0.0));
    const Lattice cc = test::make_lattice(LatticeType::CC, {40, 40, 40}, 1.0 / 39, Vec3d(0.0));
    BccSolveReport report;
    std::vector<double> values;
    for (int64_t i = 0; i < bcc.num_points(); ++i) values.push_back(cubic(bcc.position(i)).value);
    HermiteData<double> dq;
    dq.lattice = bcc;
    dq.values = values;
    dq.higher = bcc_box_quintic_coefficients(bcc, values, SplinePrefilter::Interpolation, 1, &report);
    dq.higher_stride = 1;
    std::printf("bcc_box_quintic interpolation solve: %d iterations, relative residual %.2e\n", report.iterations,
                report.relative_residual);
    EXPECT_LE(report.iterations, 40);
    EXPECT_LT(report.relative_residual, 1e-13);
    const HermiteData<double> dc = test::spline_data<CcBspline3>(cc, cubic);
    std::printf("%-16s %-14s %-12s %-12s\n", "filter", "margin (h)", "max |e|", "max |grad e|");
    Worst q[3], c[3];
    const double margins[3] = {3, 6, 12};
    for (int m = 0; m < 3; ++m) {
        q[m] = worst_error<BccBoxQuintic>(dq, cubic, inner_box(bcc, 2 * margins[m]), 21, 1000);
        c[m] = worst_error<CcBspline3>(dc, cubic, inner_box(cc, margins[m]), 22, 1000);
        std::printf("%-16s %-14.0f %-12.2e %-12.2e\n%-16s %-14.0f %-12.2e %-12.2e\n", "bcc_box_quintic", margins[m],
                    q[m].value, q[m].gradient, "cc_bspline3", margins[m], c[m].value, c[m].gradient);
    }
    EXPECT_LT(q[2].value, 1e-12);
    EXPECT_LT(q[2].gradient, 1e-10);
    EXPECT_LT(c[2].value, 1e-8);
    EXPECT_LT(c[2].gradient, 1e-5);
    EXPECT_GT(c[1].value / c[2].value, 1000.0);  // geometric decay, not a floor
    EXPECT_GT(q[1].value / q[2].value, 1000.0);
}

/// Values moved by the lattice symmetry g about the centre of a cubic lattice.
std::vector<double> transformed(const Lattice& l, const std::vector<double>& values, const test::SignedPermutation& g) {
    const int centre = l.resolution.x - 1;  // top / 2 in units of h/2
    std::vector<double> out(values.size());
    for (int64_t i = 0; i < l.num_points(); ++i) {
        const Int3 k = l.coords_of(i);
        const Int3 moved = g.apply(Int3{k.x - centre, k.y - centre, k.z - centre});
        out[size_t(l.index_of_coords({moved.x + centre, moved.y + centre, moved.z + centre}))] = values[size_t(i)];
    }
    return out;
}

template <typename I>
void check_symmetry(const Lattice& l) {
    std::mt19937 rng(30);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double> values(size_t(l.num_points()));
    for (double& x : values) x = u(rng);
    const HermiteData<double> d = test::spline_data_from_values<I>(l, values);
    const Vec3d centre = (l.domain_min() + l.domain_max()) * 0.5;
    const auto group = test::cubic_group();
    const auto points = test::random_points(rng, I::domain(d.view()), 200);
    double worst = 0, worst_gradient = 0;
    for (size_t n = 0; n < group.size(); n += 5) {  // a spread of 10 of the 48
        const HermiteData<double> dg = test::spline_data_from_values<I>(l, transformed(l, values, group[n]));
        for (const Vec3d& p : points) {
            const auto a = I::evaluate(d.view(), p), b = I::evaluate(dg.view(), centre + group[n].apply(p - centre));
            worst = std::max(worst, std::abs(a.value - b.value));
            worst_gradient = std::max(worst_gradient, length(group[n].apply(a.gradient) - b.gradient));
        }
    }
    EXPECT_LT(worst, 1e-13) << I::name();
    EXPECT_LT(worst_gradient, 1e-11) << I::name();
}

TEST(BoxSplineFilters, CommuteWithTheLatticeSymmetries) {
    const Lattice bcc = test::make_lattice(LatticeType::BCC, {9, 9, 9}, 0.5, Vec3d(0.0));
    const Lattice cc = test::make_lattice(LatticeType::CC, {9, 9, 9}, 0.5, Vec3d(0.0));
    check_symmetry<BccBoxLinear>(bcc);
    check_symmetry<BccBoxQuintic>(bcc);
    check_symmetry<BccBoxQuinticQi>(bcc);
    check_symmetry<BccBoxQuinticApprox>(bcc);
    check_symmetry<CcBspline3>(cc);
}

template <typename I>
void check_gradient_by_differences(const HermiteData<double>& d, unsigned seed) {
    std::mt19937 rng(seed);
    const double e = 1e-6 * d.lattice.spacing;
    double worst = 0, scale = 0;
    for (const Vec3d& p : test::random_points(rng, inner_box(d.lattice, 2), 500)) {
        const auto s = eval<I>(d, p);
        for (int a = 0; a < 3; ++a) {
            Vec3d step(0.0);
            step[a] = e;
            const double fd = (eval<I>(d, p + step).value - eval<I>(d, p - step).value) / (2 * e);
            worst = std::max(worst, std::abs(fd - s.gradient[a]));
            scale = std::max(scale, std::abs(s.gradient[a]));
        }
    }
    EXPECT_LT(worst, 1e-6 * scale) << I::name();
}

TEST(BoxSplineFilters, GradientsAreTheSplinesDerivatives) {
    const TrigFunction<double> f{3.0};
    check_gradient_by_differences<BccBoxQuintic>(test::spline_data<BccBoxQuintic>(kBcc, f), 40);
    check_gradient_by_differences<BccBoxQuinticQi>(test::spline_data<BccBoxQuinticQi>(kBcc, f), 41);
    check_gradient_by_differences<BccBoxQuinticApprox>(test::spline_data<BccBoxQuinticApprox>(kBcc, f), 42);
    check_gradient_by_differences<CcBspline3>(test::spline_data<CcBspline3>(kCc, f), 43);
}

template <typename I>
void check_outside_and_float(const HermiteData<double>& d) {
    const LatticeFieldView<double> v = d.view();
    const DomainBox<double> box = I::domain(v);
    const Vec3d mid = (box.lo + box.hi) * 0.5;
    EXPECT_TRUE(I::evaluate(v, mid).inside) << I::name();
    const auto outside = I::evaluate(v, Vec3d(box.hi.x + 0.7, mid.y, box.lo.z - 3.0));
    EXPECT_FALSE(outside.inside) << I::name();
    EXPECT_NEAR(outside.value, I::evaluate(v, Vec3d(box.hi.x, mid.y, box.lo.z)).value, 1e-12) << I::name();
    EXPECT_FALSE(std::isnan(I::evaluate(v, Vec3d(NAN, 0.0, 0.0)).value)) << I::name();
    const HermiteData<float> df = convert_hermite_data<float>(d);
    std::mt19937 rng(50);
    double worst = 0;
    for (const Vec3d& p : test::random_points(rng, box, 300))
        worst = std::max(worst, std::abs(double(I::evaluate(df.view(), Vec3f(p)).value) - I::evaluate(v, p).value));
    EXPECT_LT(worst, 2e-5) << I::name();
}

TEST(BoxSplineFilters, OutsidePointsAreClampedAndFloatAgreesWithDouble) {
    const TrigFunction<double> f{1.0};
    check_outside_and_float<BccBoxLinear>(test::spline_data<BccBoxLinear>(kBcc, f));
    check_outside_and_float<BccBoxQuintic>(test::spline_data<BccBoxQuintic>(kBcc, f));
    check_outside_and_float<BccBoxQuinticQi>(test::spline_data<BccBoxQuinticQi>(kBcc, f));
    check_outside_and_float<BccBoxQuinticApprox>(test::spline_data<BccBoxQuinticApprox>(kBcc, f));
    check_outside_and_float<CcBspline3>(test::spline_data<CcBspline3>(kCc, f));
}

TEST(BoxSplineFilters, PrefiltersRejectBadInput) {
    const std::vector<double> few(10, 0.0);
    EXPECT_THROW(cc_bspline3_coefficients(kCc, few), std::invalid_argument);
    EXPECT_THROW(cc_bspline3_coefficients(kBcc, std::vector<double>(size_t(kBcc.num_points()))), std::invalid_argument);
    EXPECT_THROW(bcc_box_quintic_coefficients(kBcc, few, SplinePrefilter::Interpolation), std::invalid_argument);
    const Lattice tiny = test::make_lattice(LatticeType::BCC, {3, 5, 5}, 0.1);
    try {
        bcc_box_quintic_coefficients(tiny, std::vector<double>(size_t(tiny.num_points())), SplinePrefilter::Interpolation);
        ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("resolution 3 on axis 0; needs >= 4"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace sdf
