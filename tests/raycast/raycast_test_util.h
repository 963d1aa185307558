// Shared helpers of the ray caster tests: the exact sphere as a sampled field (values and
// gradients from the formula, so the truth does not come from a sampler or the code under
// test), its analytic ray intersection, and lattices around it.
#pragma once

#include <cmath>

#include "core/lattice/lattice_fitting.h"
#include "core/reconstruction/analytic_study.h"
#include "kernels/raycast/camera.h"

namespace sdf::test {

struct Sphere {
    Vec3d centre{0.013, -0.021, 0.017};  // off the lattice's symmetry
    double radius = 0.6;

    Bounds3 bounds() const {
        Bounds3 b;
        b.extend(centre - Vec3d(radius));
        b.extend(centre + Vec3d(radius));
        return b;
    }
    AnalyticSample<double> operator()(const Vec3d& p) const {
        AnalyticSample<double> s;
        const Vec3d d = p - centre;
        const double r = length(d);
        s.value = r - radius;
        s.gradient = r > 0 ? d / r : Vec3d(1, 0, 0);
        return s;
    }
    /// Nearest intersection t >= 0 of a unit-direction ray, or -1.
    double intersect(const Ray<double>& ray) const {
        const Vec3d o = ray.origin - centre;
        const double b = dot(o, ray.direction), c = dot(o, o) - radius * radius;
        const double disc = b * b - c;
        if (disc < 0) return -1;
        const double t = -b - std::sqrt(disc);
        return t >= 0 ? t : -1;
    }
};

/// The sphere's exact distance field on a lattice fitted around it (margin 15%).
inline SampledField sphere_field(const Sphere& s, LatticeType type, Int3 resolution) {
    return sample_analytic_field(fit_lattice(type, resolution, s.bounds(), 0.15), s);
}

}  // namespace sdf::test
