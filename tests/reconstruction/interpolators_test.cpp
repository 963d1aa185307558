// Every interpolator through the host Reconstruction: lattice values reproduced, polynomial
// reproduction (exact derivative data and every derivative source), Catmull-Rom = tricubic
// with central differences, clamping outside the domain, and the float kernels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "reconstruction_test_util.h"

namespace sdf {
namespace {

const Lattice kCc = test::make_lattice(LatticeType::CC, {7, 6, 8}, 0.25);
const Lattice kBcc = test::make_lattice(LatticeType::BCC, {7, 6, 8}, 0.25);

const Lattice& lattice_for(InterpolatorKind k) { return interpolator_lattice(k) == LatticeType::CC ? kCc : kBcc; }

/// Largest error relative to the function's largest magnitude over the probes.
struct Worst {
    double value = 0, gradient = 0, scale = 0, gscale = 0;
    void add(const ReconstructedSample<double>& got, const AnalyticSample<double>& want) {
        value = std::max(value, std::abs(got.value - want.value));
        gradient = std::max(gradient, length(got.gradient - want.gradient));
        scale = std::max(scale, std::abs(want.value));
        gscale = std::max(gscale, length(want.gradient));
    }
    double relative_value() const { return value / std::max(scale, 1e-300); }
    double relative_gradient() const { return gradient / std::max(gscale, 1e-300); }
};

template <typename F>
Worst probe(const Reconstruction& r, const F& f, int n, unsigned seed) {
    std::mt19937 rng(seed);
    Worst w;
    for (const Vec3d& p : test::random_points(rng, r.domain(), n)) w.add(r.evaluate(p), f(p));
    return w;
}

TEST(Interpolators, ReproduceTheLatticeValues) {
    const TrigFunction<double> f{3.0};
    for (const ReconstructionSpec& spec : test::all_valid_specs()) {
        const Lattice& l = lattice_for(spec.interpolator);
        const Reconstruction r(sample_analytic_field(l, f), spec);
        const bool interpolating = visit_interpolator(spec.interpolator, [](auto i) { return decltype(i)::interpolating(); });
        if (!interpolating) continue;  // the quasi-interpolating and approximating splines (box_spline_filters_test)
        const DomainBox<double> box = r.domain();
        int checked = 0;
        for (int64_t i = 0; i < l.num_points(); ++i) {
            const Vec3d p = l.position(i);
            if (p.x < box.lo.x - 1e-12 || p.y < box.lo.y - 1e-12 || p.z < box.lo.z - 1e-12 || p.x > box.hi.x + 1e-12 ||
                p.y > box.hi.y + 1e-12 || p.z > box.hi.z + 1e-12)
                continue;
            EXPECT_NEAR(r.evaluate(p).value, r.data().values[size_t(i)], 1e-12) << describe(spec) << " point " << i;
            ++checked;
        }
        EXPECT_GT(checked, 100) << describe(spec);
    }
}

TEST(Interpolators, CubicSchemesReproduceEveryCubicGivenExactDerivatives) {
    std::mt19937 rng(31);
    for (InterpolatorKind k : {kind_of<TricubicLekienMarsden>(), kind_of<BccCubic>(), kind_of<BccCubicC0>()}) {
        for (int trial = 0; trial < 3; ++trial) {
            const CubicPolynomial<double> p = test::random_cubic(rng);
            const HermiteData<double> d = test::exact_hermite_data(lattice_for(k), k, p);
            const LatticeFieldView<double> v = d.view();
            const DomainBox<double> box = visit_interpolator(k, [&](auto i) { return decltype(i)::domain(v); });
            Worst w;
            for (const Vec3d& x : test::random_points(rng, box, 500)) w.add(test::evaluate(k, v, x), p(x));
            EXPECT_LT(w.relative_value(), 1e-10) << interpolator_name(k);
            EXPECT_LT(w.relative_gradient(), 1e-10) << interpolator_name(k);
        }
    }
}

TEST(Interpolators, EveryDerivativeSourceOfTheCubicSchemesReproducesCubics) {
    // true: sampled gradients; fd / fd_weighted: 27-point fits (exact for cubics); on CC the
    // cross derivatives of true gradients are central differences, exact for cubics too.
    std::mt19937 rng(32);
    const CubicPolynomial<double> p = test::random_cubic(rng);
    for (const ReconstructionSpec& spec : test::all_valid_specs()) {
        const bool cubic = spec.interpolator == kind_of<BccCubic>() ||
                           spec.interpolator == kind_of<BccCubicC0>() ||
                           (spec.interpolator == kind_of<TricubicLekienMarsden>() && spec.derivatives == DerivativeSource::True);
        if (!cubic) continue;
        const Reconstruction r(sample_analytic_field(lattice_for(spec.interpolator), p), spec);
        const Worst w = probe(r, p, 1000, 33);
        EXPECT_LT(w.relative_value(), 1e-10) << describe(spec);
        EXPECT_LT(w.relative_gradient(), 1e-10) << describe(spec);
    }
}

/// A polynomial with c[i][j][k] = 0 unless i, j, k <= max_per_axis and i + j + k <= max_total.
TricubicPolynomial<double> restricted_polynomial(std::mt19937& rng, int max_per_axis, int max_total) {
    TricubicPolynomial<double> p = test::random_tricubic(rng);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k)
                if (i > max_per_axis || j > max_per_axis || k > max_per_axis || i + j + k > max_total) p.c[i][j][k] = 0;
    return p;
}

TEST(Interpolators, LowerOrderSchemesReproduceTheirPolynomials) {
    std::mt19937 rng(34);
    struct Case {
        InterpolatorKind kind;
        int per_axis, total;
    };
    // trilinear: the trilinear span; bcc_linear: linear; Catmull-Rom and tricubic_lm with
    // central differences: every polynomial of degree 2 per axis... (quadratic precision)
    for (const Case& c : {Case{kind_of<Trilinear>(), 1, 3}, Case{kind_of<BccLinear>(), 1, 1},
                          Case{kind_of<CatmullRom>(), 2, 6}, Case{kind_of<TricubicLekienMarsden>(), 2, 6}}) {
        const TricubicPolynomial<double> p = restricted_polynomial(rng, c.per_axis, c.total);
        ReconstructionSpec spec{c.kind, DerivativeSource::FiniteDifferences};
        const Reconstruction r(sample_analytic_field(lattice_for(c.kind), p), spec);
        const Worst w = probe(r, p, 1000, 35);
        EXPECT_LT(w.relative_value(), 1e-10) << describe(spec);
        EXPECT_LT(w.relative_gradient(), 1e-10) << describe(spec);
    }
}

TEST(Interpolators, CatmullRomEqualsTricubicWithCentralDifferences) {
    const SampledField field = sample_analytic_field(kCc, TrigFunction<double>{4.0});
    const Reconstruction cr(field, {kind_of<CatmullRom>(), DerivativeSource::FiniteDifferences});
    const Reconstruction lm(field, {kind_of<TricubicLekienMarsden>(), DerivativeSource::FiniteDifferences});
    std::mt19937 rng(36);
    for (const Vec3d& p : test::random_points(rng, cr.domain(), 2000)) {
        const auto a = cr.evaluate(p), b = lm.evaluate(p);
        EXPECT_NEAR(a.value, b.value, 1e-12);
        EXPECT_LT(length(a.gradient - b.gradient), 1e-11);
    }
}

TEST(Interpolators, PointsOutsideTheDomainAreClampedAndFlagged) {
    for (const ReconstructionSpec& spec : test::all_valid_specs()) {
        const Reconstruction r(sample_analytic_field(lattice_for(spec.interpolator), TrigFunction<double>{}), spec);
        const DomainBox<double> box = r.domain();
        const Vec3d inside_point = (box.lo + box.hi) * 0.5;
        EXPECT_TRUE(r.evaluate(inside_point).inside);
        const Vec3d outside(box.hi.x + 0.7, inside_point.y, box.lo.z - 3.0);
        const ReconstructedSample<double> s = r.evaluate(outside);
        EXPECT_FALSE(s.inside) << describe(spec);
        const ReconstructedSample<double> clamped = r.evaluate(Vec3d(box.hi.x, inside_point.y, box.lo.z));
        EXPECT_NEAR(s.value, clamped.value, 1e-12) << describe(spec);
        EXPECT_FALSE(std::isnan(r.evaluate(Vec3d(NAN, 0.0, 0.0)).value)) << describe(spec);
    }
}

TEST(Interpolators, FloatKernelsAgreeWithDouble) {
    for (const ReconstructionSpec& spec : test::all_valid_specs()) {
        const Reconstruction r(sample_analytic_field(lattice_for(spec.interpolator), TrigFunction<double>{}), spec);
        const HermiteData<float> df = convert_hermite_data<float>(r.data());
        const LatticeFieldView<float> vf = df.view();
        std::mt19937 rng(37);
        double worst = 0;
        for (const Vec3d& p : test::random_points(rng, r.domain(), 300)) {
            const auto got = visit_interpolator(spec.interpolator,
                                                [&](auto i) { return decltype(i)::evaluate(vf, Vec3f(p)); });
            worst = std::max(worst, std::abs(double(got.value) - r.evaluate(p).value));
        }
        EXPECT_LT(worst, 2e-5) << describe(spec);
    }
}

}  // namespace
}  // namespace sdf
