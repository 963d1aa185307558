/// @file certified_winding.h
/// @brief The certified winding sign: the side of 1/2 of the exact generalized winding number
/// w = sum Omega_i / 4 pi, decided from double evaluations with rigorous error bounds, so that
/// it depends on the mesh and the point only, never on the tree. Host and device.
///
/// The ladder (certified_winding_side): (1) the fast evaluation (fast_winding_number.h's
/// traversal, beta 2, order 2) returns w_f and a bound B_f on |w_f - w| that covers the
/// truncation of the far field and the rounding of every term and sum; where
/// |w_f - 1/2| > B_f the side is certain ("fast"). (2) Otherwise the same traversal with a
/// stricter opening rule, beta times `refine_factor`, up to `refinements` times ("refined").
/// (3) Otherwise the direct sum over every triangle in mesh order, with its rounding bound
/// ("direct"). (4) Where even that bound reaches 1/2 the point is a tie ("tie"): it gets the
/// outside side, i.e. inside means w > 1/2 proven. Ties are points on the surface (within
/// rounding of a triangle, where Omega jumps by 4 pi and w is undefined) and points whose w is
/// 1/2 to within about 1e-13 (a hole's spanning surface through a symmetric hole).
///
/// Rounding bounds (u = 2^-53, the standard model fl(a op b) = (a op b)(1 + d), |d| <= u):
/// - One solid angle, Omega = 2 atan2(N, D) (solid_angle.h). With a, b, c the corners minus p
///   and S = |a||b||c|, the computed N and D are within E = 128 u S of the exact values of the
///   exact corners (N: the differences, the cross and dot products, gamma_8 |a|.(|b| x |c|)
///   <= 8 u 3 sqrt(3) S; D: four terms of magnitude <= S, lengths within 3u, about 53 u S;
///   |(dN, dD)| <= 80 u S, doubled for the second-order terms). If (N, D) is R from the
///   origin and E < R, the direction of (N, D) moves by at most asin(E / R) <= pi E / (2R), and
///   atan2 adds at most 2 ulp of pi: |dOmega| <= pi E / R + 8 pi u. Where E >= R, or the
///   disc of radius E around (N, D) reaches atan2's cut (D < 0, |N| <= E: p within rounding
///   of the triangle itself), |dOmega| <= 4 pi: the point is undecided by this triangle.
/// - A far-field term (fast_winding_number.h): the truncation bound with the radius and area
///   raised by their own rounding (r' = r (1 + 8u) + 4u X, X the largest coordinate
///   magnitude of mesh and point; the moments are sums of up to n triangles' terms, so A, N
///   and M are within 128 u (n + 8) (A + r^2) of exact, centres within as much of X), plus
///   the term's own rounding, 128 u (n + 8) (A + r^2) (1 + X / d) / (4 pi d^2).
/// - Every sum: a running bound, u |s| per addition (fl(s + x) = (s + x)(1 + d)), and the
///   final bound times (1 + 128 u (n + 8)) for the rounding of the bound's own sum.
/// These are first-order bounds with constants about twice what the derivation needs.
#pragma once

#include <cmath>
#include <cstdint>

#include "kernels/winding/fast_winding_number.h"

namespace sdf {

/// u = 2^-53, the unit roundoff of double.
constexpr double kWindingUnitRoundoff = 1.1102230246251565404e-16;
constexpr double kWindingPi = 3.14159265358979323846;

/// How a certified side was decided (the manifest's counters: sampler_report.h). Surface:
/// by the first stage, a triangle's front winding number and the triangles the segment to
/// its centroid crosses (surface_side.h), before the ladder; Nearest: by the point's nearest
/// triangles alone, those a certified search could not rule out, with no walk of the tree
/// (nearest_side, surface_side.h).
enum class WindingStage : uint8_t { Fast = 0, Refined = 1, Direct = 2, Tie = 3, Surface = 4, Nearest = 5 };
constexpr int kWindingStages = 6;

struct WindingSide {
    bool inside = false;
    WindingStage stage = WindingStage::Fast;
};

/// The refinement ladder after the fast evaluation (the same on every backend).
struct WindingCertification {
    double refine_factor = 2.0;  ///< beta grows by this factor per refinement (4, 8, 16)
    int refinements = 3;         ///< then the direct sum
};

/// What the rounding bounds need of the mesh: 128 u (n + 8) and X (largest |coordinate|).
struct WindingRounding {
    double n_factor = 0;
    double scale = 0;
};

SDF_CPU_GPU SDF_INLINE WindingRounding winding_rounding(const WindingView<double>& v, const Vec3d& q) {
    WindingRounding r;
    r.n_factor = 128.0 * kWindingUnitRoundoff * (double(v.num_triangles) + 8.0);
    r.scale = fmax(v.scale, fmax(fabs(q.x), fmax(fabs(q.y), fabs(q.z))));
    return r;
}

/// The solid angle's rounding error bound from its computed N, D and S = |a||b||c|.
SDF_CPU_GPU SDF_INLINE double solid_angle_rounding(double numerator, double denominator, double S) {
    const double u = kWindingUnitRoundoff;
    const double E = 128.0 * u * S;
    const double R = hypot(numerator, denominator) * (1.0 - 4.0 * u);
    if (!(E < R) || (denominator < 0.0 && fabs(numerator) <= E)) return 4.0 * kWindingPi;
    return (kWindingPi * E / R + 8.0 * kWindingPi * u) * (1.0 + 8.0 * u);
}

/// N, D and S = |a||b||c| of one triangle seen from p: the one formula of
/// certified_solid_angle() and of the CPU's packets (certified_winding_packet.h).
SDF_CPU_GPU SDF_INLINE void certified_solid_angle_terms(const Vec3d& p, const Vec3d& v0, const Vec3d& v1, const Vec3d& v2,
                                                        double& numerator, double& denominator, double& S) {
    const Vec3d a = v0 - p, b = v1 - p, c = v2 - p;
    const double la = length(a), lb = length(b), lc = length(c);
    numerator = dot(a, cross(b, c));
    S = la * lb * lc;
    denominator = S + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    // Below these, squares and products leave the normal range, where rounding is absolute
    // (a length from a subnormal square can be wrong by 100%) and 128 u S bounds nothing:
    // the triangle decides nothing (solid_angle_rounding() gives 4 pi for S = inf).
    if (!(fmin(la, fmin(lb, lc)) > 0x1p-450) || !(S > 0x1p-900)) S = INFINITY;
}

/// Omega of one triangle seen from p, with the bound on its rounding.
SDF_CPU_GPU SDF_INLINE double certified_solid_angle(const Vec3d& p, const Vec3d& v0, const Vec3d& v1, const Vec3d& v2,
                                                    double& error) {
    double numerator, denominator, S;
    certified_solid_angle_terms(p, v0, v1, v2, numerator, denominator, S);
    error = solid_angle_rounding(numerator, denominator, S);
    return 2.0 * atan2(numerator, denominator);
}

/// A running sum with its error bound: value, and bound >= |value - exact sum of the terms'
/// exact values| given each term's own bound.
struct CertifiedSum {
    double value = 0, bound = 0;
    SDF_CPU_GPU SDF_INLINE void add(double term, double term_bound) {
        value += term;
        bound += term_bound + kWindingUnitRoundoff * fabs(value);
    }
};

/// The leaf's (or the whole mesh's) solid angles over 4 pi, added to `sum` as one term.
SDF_CPU_GPU SDF_INLINE void add_solid_angles(CertifiedSum& sum, double omega_sum, double omega_bound) {
    const double u = kWindingUnitRoundoff;
    const double w = omega_sum * inverse_four_pi<double>();
    sum.add(w, omega_bound * inverse_four_pi<double>() * (1.0 + 2.0 * u) + 2.0 * u * fabs(w));
}

SDF_CPU_GPU SDF_INLINE void certified_leaf(CertifiedSum& sum, const WindingView<double>& v, int32_t first, int32_t count,
                                           const Vec3d& q) {
    double s = 0, e = 0;
    for (int32_t slot = first; slot < first + count; ++slot) {
        const Int3 t = v.triangles[v.triangle_index[slot]];
        double err;
        s += certified_solid_angle(q, v.vertices[t.x], v.vertices[t.y], v.vertices[t.z], err);
        e += err + kWindingUnitRoundoff * fabs(s);
    }
    add_solid_angles(sum, s, e);
}

/// The far-field term of one child at y = p~ - q, d2 = |y|^2 (q far: d2 > far_limit), with
/// its certified bound (truncation and rounding): the one formula of certified_far_field()
/// and of the CPU's packets (certified_winding_packet.h).
SDF_CPU_GPU SDF_INLINE void certified_far_term(const WindingMoments<double>& m, const Vec3d& y, double d2, int order,
                                               const WindingRounding& rnd, double& value, double& bound) {
    const double u = kWindingUnitRoundoff;
    const double d = sqrt(d2), inv_d = 1.0 / d, inv_d3 = inv_d * inv_d * inv_d;
    value = far_field_value(m, y, inv_d, inv_d3, order);
    const double r = m.radius * (1.0 + 8.0 * u) + 4.0 * u * rnd.scale;
    const double t = r * inv_d * (1.0 + 4.0 * u);
    const double mass = (m.area + rnd.n_factor * r * r) * inv_d * inv_d;
    const double rounding = rnd.n_factor * (m.area + r * r) * (1.0 + rnd.scale * inv_d) * inv_d * inv_d;
    const double one_minus_t = 1.0 - t;
    const double series = order >= 2 ? t * t * (3.0 - 2.0 * t) : t * (2.0 - t);
    bound = (mass * series / (one_minus_t * one_minus_t) + rounding) * inverse_four_pi<double>() * (1.0 + 16.0 * u);
    // The radius's rounding ate the margin (a far-away tiny cluster), or the cluster is so
    // close that the terms' products leave the normal range: no bound.
    if (!(t < 0.75) || !(d2 > 0x1p-900)) bound = INFINITY;
}

/// The far-field term of one child with its certified bound; false when q is not far enough
/// (the opening rule of far_field()).
SDF_CPU_GPU SDF_INLINE bool certified_far_field(const WindingMoments<double>& m, const Vec3d& q,
                                                const WindingAccuracy<double>& acc, const WindingRounding& rnd,
                                                double& value, double& bound) {
    const Vec3d y = m.center - q;
    const double d2 = length_squared(y);
    if (!(d2 > far_limit(m, acc))) return false;
    certified_far_term(m, y, d2, acc.order, rnd, value, bound);
    return true;
}

/// The estimate's final bound: the running bound raised for its own rounding.
SDF_CPU_GPU SDF_INLINE WindingEstimate<double> certified_estimate(const CertifiedSum& s, const WindingRounding& rnd, int opened) {
    WindingEstimate<double> e;
    e.value = s.value;
    e.error_bound = s.bound * (1.0 + rnd.n_factor);
    e.opened = opened;
    return e;
}

/// The fast winding number of q with a certified bound (truncation and rounding): the
/// traversal of fast_winding_number(), the same children accepted.
SDF_CPU_GPU inline WindingEstimate<double> certified_winding_number(const WindingView<double>& v, const Vec3d& q,
                                                                    const WindingAccuracy<double>& acc) {
    const WindingRounding rnd = winding_rounding(v, q);
    CertifiedSum sum;
    int opened = 0;
    int32_t stack[kBvhMaxDepth + 1];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const int32_t node = stack[--top];
        ++opened;
        const BvhNode& n = v.nodes[node];
        for (int c = 0; c < 2; ++c) {
            double value, bound;
            if (certified_far_field(v.moments[node].child[c], q, acc, rnd, value, bound)) {
                sum.add(value, bound);
            } else if (bvh_child_is_leaf(n, c)) {
                certified_leaf(sum, v, n.ref[c], n.count[c], q);
            } else {
                SDF_DCHECK(top <= kBvhMaxDepth);
                stack[top++] = n.ref[c];
            }
        }
    }
    return certified_estimate(sum, rnd, opened);
}

/// The direct sum over every triangle, in mesh order (no tree: the same bits on any tree),
/// with its rounding bound.
SDF_CPU_GPU inline WindingEstimate<double> certified_winding_direct(const WindingView<double>& v, const Vec3d& q) {
    const WindingRounding rnd = winding_rounding(v, q);
    double s = 0, e = 0;
    for (int i = 0; i < v.num_triangles; ++i) {
        const Int3 t = v.triangles[i];
        double err;
        s += certified_solid_angle(q, v.vertices[t.x], v.vertices[t.y], v.vertices[t.z], err);
        e += err + kWindingUnitRoundoff * fabs(s);
    }
    CertifiedSum sum;
    add_solid_angles(sum, s, e);
    return certified_estimate(sum, rnd, 0);
}

/// True when the estimate proves its side of 1/2.
SDF_CPU_GPU SDF_INLINE bool winding_decides(const WindingEstimate<double>& e) {
    return fabs(e.value - 0.5) > e.error_bound;
}

/// The certified side after a fast estimate `first` (certified_winding_number at `acc`) that
/// did not decide: the refinements, then the direct sum, then the tie rule (outside).
SDF_CPU_GPU inline WindingSide certified_winding_refine(const WindingView<double>& v, const Vec3d& q,
                                                        const WindingAccuracy<double>& acc, const WindingCertification& cert) {
    WindingAccuracy<double> finer = acc;
    for (int k = 0; k < cert.refinements; ++k) {
        finer.beta *= cert.refine_factor;
        const WindingEstimate<double> e = certified_winding_number(v, q, finer);
        if (winding_decides(e)) return {e.value > 0.5, WindingStage::Refined};
    }
    const WindingEstimate<double> e = certified_winding_direct(v, q);
    if (winding_decides(e)) return {e.value > 0.5, WindingStage::Direct};
    return {false, WindingStage::Tie};
}

/// The certified side of q: sign(w - 1/2) of the exact winding number, ties outside.
SDF_CPU_GPU inline WindingSide certified_winding_side(const WindingView<double>& v, const Vec3d& q,
                                                      const WindingAccuracy<double>& acc, const WindingCertification& cert) {
    const WindingEstimate<double> e = certified_winding_number(v, q, acc);
    if (winding_decides(e)) return {e.value > 0.5, WindingStage::Fast};
    return certified_winding_refine(v, q, acc, cert);
}

}  // namespace sdf
