/// @file march.h
/// @brief Finds where a ray first meets the zero level set of a reconstruction: enter the
/// interpolator's domain box, step until the first sign change, refine the bracket. Written
/// once for host and device and templated on the interpolator type (interpolator.h), so
/// every interpolator, CC or BCC, with any derivative source, is cast by the same code.
///
/// Step rule (docs/raycast.md has the argument in full). From a point with value f > 0:
///
///   dt = max(dt_min, kappa * f),   kappa = 1/2,   dt_min = 1/4 lattice unit
///
/// (lattice unit = h on CC, h/2 on BCC), cut at the exit of the box. Guarantee:
///  - A Lipschitz step kappa * f cannot pass a root as long as the reconstruction's slope
///    along the ray stays below 1/kappa = 2 on the step (the exact distance field has slope
///    <= 1, so this leaves a factor 2 for reconstruction error): the value cannot fall from
///    f to 0 in less than f / 2.
///  - A floor step dt_min (taken only where f < 2 dt_min, i.e. within half a lattice unit of
///    the surface) can miss only a negative interval shorter than dt_min: a solid less than
///    a quarter of a lattice unit thick along the ray, far below what samples one lattice
///    unit apart resolve, or a ray grazing the surface over less than that. For grazing
///    rays the step also checks for a dip: when f > 0 at both ends but the directional
///    derivative goes from negative to positive, the cubic Hermite model of f on the step
///    (from the values and directional derivatives at its ends, which evaluate() returns
///    anyway) predicts the minimum; if the prediction is below dt_min / 8, f is evaluated
///    there and a negative value brackets a root.
///  - Every step is at least dt_min, so a ray takes at most length / dt_min steps.
///
/// Refinement: the bracket [ta, tb] with f(ta) > 0 >= f(tb) is shrunk by the Illinois
/// variant of regula falsi (secant steps that keep the bracket; the retained end's value is
/// halved when the same end is kept twice, which makes it converge superlinearly), falling
/// back to bisection whenever the secant point leaves the bracket, until the bracket is
/// narrower than 1e-3 lattice units (or 40 iterations). The hit is the secant point of the
/// final bracket, and the normal is the reconstructed gradient there. For a discontinuous
/// interpolator (bcc_cubic) the bracket may close on a jump instead of a root; the hit is
/// then the jump's location.
///
/// Rays that start inside: if f <= 0 at the point where the ray enters the domain box (the
/// solid is cut by the box, or the eye is inside the solid), the hit is that entry point
/// (HitKind::Clipped) and its normal is the box face's normal (-direction when the eye is
/// inside the box): the rendered surface is the boundary of {f <= 0} clipped to the box.
#pragma once

#include "kernels/raycast/pixel_record.h"
#include "kernels/raycast/ray_box.h"
#include "kernels/reconstruction/lattice_field_view.h"

namespace sdf {

/// The march's constants, in lattice units where they are lengths.
template <typename T>
struct MarchSettings {
    T lipschitz_fraction = T(0.5);   ///< kappa: step = kappa * f away from the surface
    T min_step_units = T(0.25);      ///< dt_min
    T tolerance_units = T(1e-3);     ///< final bracket width
    int max_refine_iterations = 40;
    bool dip_check = true;           ///< look for a root inside steps with a local minimum

    template <typename U>
    SDF_CPU_GPU MarchSettings<U> as() const {
        return {U(lipschitz_fraction), U(min_step_units), U(tolerance_units), max_refine_iterations, dip_check};
    }
};

template <typename T>
struct MarchResult {
    HitKind hit = HitKind::Miss;
    T t{};               ///< ray parameter of the hit
    Vec3<T> gradient{};  ///< reconstructed gradient at the hit (Clipped: the face normal)
    int steps = 0;       ///< evaluations while stepping (the refinement not included)
    int refine_iterations = 0;
};

/// Value and directional derivative of the field along the ray at t.
template <typename T>
struct RayFieldSample {
    T t{}, f{}, df{};
    Vec3<T> gradient{};
};

template <typename Interp, typename T>
SDF_CPU_GPU RayFieldSample<T> sample_along(const LatticeFieldView<T>& view, const Ray<T>& ray, T t) {
    const ReconstructedSample<T> s = Interp::evaluate(view, ray.at(t));
    return {t, s.value, dot(s.gradient, ray.direction), s.gradient};
}

/// Minimiser in (0, len) of the cubic Hermite interpolant of (f0, df0) at 0 and (f1, df1) at
/// len, for df0 < 0 < df1 (then its derivative changes sign exactly once in (0, len));
/// returns the offset and writes the model's value there to *model_min.
template <typename T>
SDF_CPU_GPU T hermite_minimiser(T f0, T df0, T f1, T df1, T len, T* model_min) {
    // p(s) = a s^3 + b s^2 + c s + d on s in [0, 1]
    const T c = len * df0, d = f0;
    const T b = T(3) * (f1 - f0) - T(2) * len * df0 - len * df1;
    const T a = T(2) * (f0 - f1) + len * df0 + len * df1;
    T lo = T(0), hi = T(1);
    for (int i = 0; i < 20; ++i) {  // bisection on p'(s) = 3a s^2 + 2b s + c (p'(0) < 0 < p'(1))
        const T s = T(0.5) * (lo + hi);
        if ((T(3) * a * s + T(2) * b) * s + c < T(0)) lo = s; else hi = s;
    }
    const T s = T(0.5) * (lo + hi);
    *model_min = ((a * s + b) * s + c) * s + d;
    return s * len;
}

/// Shrinks a bracket a.f > 0 >= b.f to `tolerance` (Illinois regula falsi, bisection
/// fallback); returns the root estimate and counts iterations in *iterations.
template <typename Interp, typename T>
SDF_CPU_GPU T refine_root(const LatticeFieldView<T>& view, const Ray<T>& ray, RayFieldSample<T> a,
                          RayFieldSample<T> b, T tolerance, int max_iterations, int* iterations) {
    T ta = a.t, fa = a.f, tb = b.t, fb = b.f;
    int kept = 0;  // +1: the lower end was replaced last, -1: the upper end
    int it = 0;
    while (it < max_iterations && tb - ta > tolerance && fb != T(0)) {
        T t = tb - fb * (tb - ta) / (fb - fa);
        if (!(t > ta && t < tb)) t = T(0.5) * (ta + tb);
        const T f = Interp::evaluate(view, ray.at(t)).value;
        ++it;
        if (f > T(0)) {
            ta = t; fa = f;
            if (kept == 1) fb *= T(0.5);
            kept = 1;
        } else {
            tb = t; fb = f;
            if (kept == -1) fa *= T(0.5);
            kept = -1;
        }
    }
    *iterations = it;
    if (fb == T(0)) return tb;
    const T t = tb - fb * (tb - ta) / (fb - fa);
    return (t >= ta && t <= tb) ? t : T(0.5) * (ta + tb);
}

/// The first point of the ray in {f <= 0} within the interpolator's domain `box` (pass
/// Interp::domain(view), computed once per image).
template <typename Interp, typename T>
SDF_CPU_GPU MarchResult<T> march_ray(const LatticeFieldView<T>& view, const DomainBox<T>& box, const Ray<T>& ray,
                                     const MarchSettings<T>& settings) {
    MarchResult<T> r;
    const RaySegment<T> segment = clip_ray_to_box(ray, box);
    if (!segment.valid) return r;
    const T min_step = settings.min_step_units * view.unit;
    RayFieldSample<T> s0 = sample_along<Interp>(view, ray, segment.t_enter);
    r.steps = 1;
    if (s0.f <= T(0)) {
        // Started inside the solid: the box face is the visible surface
        r.hit = HitKind::Clipped;
        r.t = segment.t_enter;
        r.gradient = entry_face_normal(ray, segment.enter_axis);
        return r;
    }
    while (s0.t < segment.t_exit) {
        const T step = settings.lipschitz_fraction * s0.f > min_step ? settings.lipschitz_fraction * s0.f : min_step;
        const T t1 = s0.t + step < segment.t_exit ? s0.t + step : segment.t_exit;
        if (!(t1 > s0.t)) break;  // no progress in this precision (cannot happen for sane scenes)
        RayFieldSample<T> s1 = sample_along<Interp>(view, ray, t1);
        ++r.steps;
        bool bracketed = s1.f <= T(0);
        if (!bracketed && settings.dip_check && s0.df < T(0) && s1.df > T(0)) {
            // Both ends outside, but f has a minimum between them: look there
            T model_min;
            const T offset = hermite_minimiser(s0.f, s0.df, s1.f, s1.df, t1 - s0.t, &model_min);
            if (model_min < T(0.125) * min_step) {
                const RayFieldSample<T> m = sample_along<Interp>(view, ray, s0.t + offset);
                ++r.steps;
                if (m.f <= T(0)) { s1 = m; bracketed = true; }
            }
        }
        if (bracketed) {
            r.hit = HitKind::Surface;
            r.t = refine_root<Interp>(view, ray, s0, s1, settings.tolerance_units * view.unit,
                                      settings.max_refine_iterations, &r.refine_iterations);
            r.gradient = Interp::evaluate(view, ray.at(r.t)).gradient;
            return r;
        }
        s0 = s1;
    }
    return r;
}

}  // namespace sdf
