// Shared helpers of the reconstruction tests: lattices, random polynomials, and Hermite data
// filled with *exact* derivatives of an analytic function (truth independent of the
// finite-difference and least-squares code under test).
#pragma once

#include <random>
#include <vector>

#include "core/reconstruction/analytic_study.h"
#include "core/reconstruction/bcc_cubic_tables.h"

namespace sdf::test {

inline Lattice make_lattice(LatticeType type, Int3 resolution, double spacing, Vec3d origin = {0.1, -0.2, 0.3}) {
    Lattice l;
    l.type = type;
    l.origin = origin;
    l.spacing = spacing;
    l.resolution = resolution;
    return l;
}

inline CubicPolynomial<double> random_cubic(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    CubicPolynomial<double> p;
    for (double& c : p.c) c = u(rng);
    return p;
}

inline TricubicPolynomial<double> random_tricubic(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    TricubicPolynomial<double> p;
    for (auto& a : p.c)
        for (auto& b : a)
            for (double& c : b) c = u(rng);
    return p;
}

/// Uniform random points in a world box.
inline std::vector<Vec3d> random_points(std::mt19937& rng, const DomainBox<double>& box, int n) {
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Vec3d> p(static_cast<size_t>(n));
    for (Vec3d& q : p) q = box.lo + component_mul(box.hi - box.lo, Vec3d(u(rng), u(rng), u(rng)));
    return p;
}

/// Hermite data of `kind` built from the exact derivatives of f (per lattice unit).
template <typename F>
HermiteData<double> exact_hermite_data(const Lattice& l, InterpolatorKind kind, const F& f) {
    HermiteData<double> d;
    d.lattice = l;
    d.higher_stride = interpolator_higher_stride(kind);
    const double u = l.type == LatticeType::CC ? l.spacing : l.half_spacing();
    const int64_t n = l.num_points();
    for (int64_t i = 0; i < n; ++i) {
        const AnalyticSample<double> s = f(l.position(i));
        d.values.push_back(s.value);
        d.first.push_back(s.gradient * u);
        const SymmetricHessian<double> h = s.hessian;
        if (d.higher_stride == kCcHigherStride) {
            for (double x : {h.xy * u * u, h.xz * u * u, h.yz * u * u, s.dxyz * u * u * u}) d.higher.push_back(x);
        } else if (d.higher_stride > 0) {
            for (double x : {h.xy, h.xz, h.yz}) d.higher.push_back(x * u * u);
            if (d.higher_stride == kBccFullStride)
                for (double x : {h.xx, h.yy, h.zz}) d.higher.push_back(x * u * u);
        }
    }
    if (kind == kind_of<BccCubic>()) d.faces = to_face_table<double>(bcc_cubic_face_weights());
    if (kind == kind_of<BccCubicC0>()) d.faces = to_face_table<double>(bcc_cubic_c0_face_weights());
    return d;
}

/// Evaluates interpolator `kind` on a view.
inline ReconstructedSample<double> evaluate(InterpolatorKind kind, const LatticeFieldView<double>& v, const Vec3d& p) {
    return visit_interpolator(kind, [&](auto interp) { return decltype(interp)::evaluate(v, p); });
}

/// Every (interpolator, derivative source) pair the factory accepts.
inline std::vector<ReconstructionSpec> all_valid_specs() {
    std::vector<ReconstructionSpec> specs;
    for (const std::string& name : interpolator_names()) {
        const InterpolatorKind k = parse_interpolator(name);
        for (DerivativeSource s : valid_derivative_sources(k)) {
            ReconstructionSpec spec;
            spec.interpolator = k;
            spec.derivatives = s;
            specs.push_back(spec);
        }
    }
    return specs;
}

}  // namespace sdf::test
