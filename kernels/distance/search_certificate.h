/// @file search_certificate.h
/// @brief The certificate that makes a float nearest-triangle search return exactly the
/// triangle of the double search: a rigorous bound on the float error of squared_distance(),
/// the candidates within it, and their re-ranking in double.
///
/// The reference ("exact") is the double search: the argmin over all triangles of
/// Q_d(t) = squared_distance() on PackedTriangle<double>, ties to the smaller triangle index
/// (wins_tie). A float search ranks by Q_f(t), the same formula on PackedTriangle<float> at
/// the point rounded to float. Where |Q_f(t) - Q_d(t)| <= E for every triangle that matters,
/// the double winner t* satisfies Q_f(t*) <= Q_d(t*) + E <= Q_d(w) + E <= Q_f(w) + 2E for the
/// float winner w. So every triangle with Q_f <= q_w + 2E (the "radius" below; Q_f less
/// sliver_excess() for the few triangles float searches by their edges only) is a candidate; a search that prunes with that radius and keeps the candidates returns t*
/// after evaluating only the candidates in double. One candidate (w itself): certified
/// without any double work. Exact ties (every triangle around the nearest vertex or edge has
/// the same exact Q) are candidates by construction, and double's own rounding decides
/// among them, as it does in the double search.
///
/// The bound E (Higham, "Accuracy and Stability of Numerical Algorithms", 2002: a sum or dot
/// product of n terms has error at most gamma_n = n u / (1 - n u) times the sum of the
/// terms' magnitudes, u = 2^-24 in float, 2^-53 in double). Write M = |B - P| + |E0| + |E1|
/// for a triangle (B = V0, E0 = V1 - V0, E1 = V2 - V0) and point P:
///  1. Inputs. The float point is fl(P), the packed B is fl(V0), and dx = fl(bx - px): the
///     difference vector is off by at most d0 + u M with d0 = sqrt(3) u (C_mesh + C_point)
///     (C = largest |coordinate|). That moves P by as much against the triangle, and a
///     squared distance (1-Lipschitz distance) moves by at most 2 M (d0 + u M) + (d0 + u M)^2.
///  2. Arithmetic on that point with constants rounded once from double (relative error u):
///     every branch value is a sum of at most 8 products whose magnitudes add up to at most
///     2 M^2 (q12: |B-P|^2 + c + |e2| + |s (de + w12)| + g s^2; the others less), each with
///     at most 8 roundings; the clamped edge parameters are off by Delta s, which raises a
///     clamped quadratic by at most min(g, g Delta s^2) <= gamma_5 M^2. In all at most
///     gamma_32 M^2 (generous).
///  3. Branch. "Inside" tests Eberly's s = sa 2d + sb 2e and t; |sa 2d| and |sb 2e| are at
///     most |B-P| / (|E0| sin^2 theta0) (theta0 the angle at V0), so the in-plane position
///     s E0 + t E1 is off by delta <= 8 gamma_4 |B-P| / sin^2 theta0. Whichever branch each
///     precision takes, the exact values of the branches differ by at most delta^2: a point
///     declared inside lies within delta of the triangle, one declared outside within delta
///     of an edge (so its edge distance exceeds the plane distance by at most delta^2).
///     With S the smallest sin^2 of the triangles a precision searches inside by (s, t)
///     (slivers never are): at most 64 gamma_5^2 M^2 / S^2 (gamma_5: the double constants' own
///     relative error, about 4 u_double / S, added to u). Float treats triangles with
///     sin^2 < kFloatSliverSin2 as slivers, so its S is at least 1e-2 and this term stays
///     below the arithmetic one. Double's slivers decide "inside" by edge functions
///     (sliver_squared_distance, packed_triangle.h): at most (64 u)^2 M^2 / S_sliver, S_sliver
///     their smallest sin^2 (>= kRobustSliverSin2).
///  4. Float slivers. Every triangle float searches by its edges (sliver_excess, x): the edge
///     distance exceeds the distance by at most the squared inradius, which the packed float
///     triangle carries: there Q_f - x <= Q_d + E and Q_d <= Q_f + E, and candidates are
///     ranked by Q_f - x.
///  Together, for float and double alike (double's terms with u = 2^-53):
///     |Q_f - Q_d| <= E(M) = rho M^2 + 2 d0 M + d0^2   (beyond x for float-only slivers),
///     rho = sum over both precisions of (gamma_32 + 64 gamma_5^2 / S^2) + 3 u
///           + (64 u_double)^2 / S_sliver where double has slivers.
/// M itself: a triangle that matters has Q_d <= D = Q_d(w) <= q + E, so its distance is at
/// most sqrt(q + 2E) and |B - P| at most that plus its diameter (<= |E0| + |E1|); with
/// L = max over the mesh of |E0| + |E1| and sqrt(E) <= sqrt(rho) M + d0 / sqrt(rho):
///     M <= k1 (sqrt(q) + 2 L + sqrt(2) d0 / sqrt(rho)),  k1 = 1 / (1 - sqrt(2 rho)).
/// The same E covers the pruning: a box's float distance exceeds the true one (at most the
/// triangle's) by less than the input and arithmetic terms above.
#pragma once

#include <cmath>
#include <limits>

#include "kernels/distance/packed_triangle.h"

namespace sdf {

/// Per-mesh constants of the bound (see the file comment), computed on the host in double
/// by float_search_bound() (core/sampling/certified_search.h).
struct FloatSearchBound {
    double rho = 0;         ///< coefficient of M^2
    double two_l = 0;       ///< 2 L
    double coordinate = 0;  ///< C_mesh: the largest |coordinate| of the mesh
    bool usable = false;    ///< false: the bound is too loose (rho too large) to certify anything
    /// rho of double alone (|Q_d - Q| <= rho_double M^2: double's points and vertices are
    /// exact, d0 = 0), for the double search's pruning margin (PruneMargin below).
    double rho_double = 0;
    /// The largest inradius of the triangles the float search ranks by their edges only
    /// (sliver_excess), and of those double ranks so (sin^2 below kRobustSliverSin2): a
    /// search's nearest triangle may lie farther than the true nearest by up to this, so a
    /// distance bound taken from one search (the narrow band's probes) is lowered by it.
    double sliver_reach_float = 0;
    double sliver_reach_double = 0;
};

/// How far beyond a search's radius a box must still be entered for the search to return
/// the brute-force argmin of the computed Q (closest_triangle_bvh.h): a triangle with
/// computed Q <= r has a true squared distance up to r + rho M^2, M <= sqrt(r) + l (the bound
/// above with M's estimate), and its box's computed distance is within a few ulps of the true
/// one. Zero (no margin) for float views: a certified float radius already holds the float
/// bound, which covers the pruning. Without it, where Q's rounding is large against Q (a point
/// much nearer a triangle than the triangle is long, or far from the origin) a box could be
/// skipped whose triangle rounds below the radius, and the winner would depend on the tree.
template <typename T>
struct PruneMargin {
    T rho = T(0), l = T(0);

    /// A computed Q, and so a radius, may round below 0 (a point on a triangle): it is widened
    /// like 0, as a true Q of 0 would be. An unused packet lane (radius -1) stays below every
    /// box while rho l^2 < 1, and otherwise only enters boxes it did not need.
    SDF_CPU_GPU SDF_INLINE T widen(T radius) const {
        if (!(rho > T(0))) return radius;             // no margin (float views)
        if (!(rho < T(INFINITY))) return T(INFINITY);  // the brute force (inf * 0 at radius 0 is NaN)
        const T m = std::sqrt(radius > T(0) ? radius : T(0)) + l;
        return radius + rho * m * m;
    }
};

/// The double search's margin of a mesh: rho_double / (1 - sqrt(rho_double))^2 (M's own
/// estimate, as in the file comment), l = 2 L, both rounded up generously; an unusable bound
/// gives an infinite margin (every box entered: the brute force).
inline PruneMargin<double> double_prune_margin(const FloatSearchBound& b) {
    PruneMargin<double> m;
    const double root = std::sqrt(b.rho_double);
    m.rho = root < 0.5 ? b.rho_double / ((1.0 - root) * (1.0 - root)) * 1.01 : INFINITY;
    m.l = b.two_l * 1.01;
    if (!std::isfinite(m.l)) m.rho = INFINITY;
    return m;
}

/// The search radius of a certified float search at one point (or a packet of points whose
/// largest |coordinate| is `point_coordinate`): every triangle with Q_f <= radius(q_best)
/// is a candidate. Constants rounded up in T; radius() adds a relative 1e-5 for its own
/// float rounding (a handful of operations on positive terms).
template <typename T>
struct SearchSlack {
    T k1 = T(0), k2 = T(0), rho = T(0), d0 = T(0), c0 = T(0);  ///< c0 = d0^2
    bool certify = false;  ///< false: radius(q) = +inf (every triangle a candidate)

    SDF_CPU_GPU SDF_INLINE T radius(T q) const {
        const T m = k1 * std::sqrt(q > T(0) ? q : T(0)) + k2;  // float Q may round below 0
        const T e = (rho * m + T(2) * d0) * m + c0;
        return certify ? (q + T(2) * e) * T(1.00001) : T(INFINITY);
    }
};

/// nearest_side()'s bound (kernels/winding/surface_side.h) from a certified search's float
/// winner Q `best_q`: a squared distance X that every triangle outside the candidates
/// exceeds in exact arithmetic. A
/// triangle U with Q(U) <= X has Q_f(U) - x <= Q(U) + E <= X + E <= radius
/// (the file comment; radius >= q + 2E, so X = q + 0.49 (radius - q) leaves room for E,
/// and X is kept within q + 2E, where the bound on M holds), so it is a candidate.
SDF_CPU_GPU inline double beyond_candidates_squared(const SearchSlack<float>& slack, float best_q) {
    const float radius = slack.radius(best_q);
    const double q = double(best_q), m = double(slack.k1) * std::sqrt(q > 0 ? q : 0.0) + double(slack.k2);
    const double e = (double(slack.rho) * m + 2.0 * double(slack.d0)) * m + double(slack.c0);
    return q + std::fmin(0.49 * (double(radius) - q), 1.9 * e);
}

/// The slack of a float search at points of largest |coordinate| `point_coordinate`.
inline SearchSlack<float> make_search_slack(const FloatSearchBound& b, double point_coordinate) {
    SearchSlack<float> s;
    if (!b.usable) return s;
    const double sqrt2rho = std::sqrt(2.0 * b.rho);
    const double d0 = std::sqrt(3.0) * 0x1p-24 * (b.coordinate + point_coordinate) * 1.01;
    const double k1 = 1.0 / (1.0 - sqrt2rho);
    const double k2 = k1 * (b.two_l + std::sqrt(2.0) * d0 / std::sqrt(b.rho));
    auto up = [](double x) { return std::nextafter(float(x), INFINITY); };
    s.k1 = up(k1 * 1.0001);
    s.k2 = up(k2 * 1.0001);
    s.rho = up(b.rho);
    s.d0 = up(d0);
    s.c0 = up(d0 * d0);
    s.certify = std::isfinite(s.k2) && std::isfinite(s.d0);
    return s;
}

/// Up to N candidate triangles (slots) with their float Q, offered while a search runs with
/// a shrinking radius. When full, the largest is dropped and `dropped` keeps the smallest Q
/// ever dropped (NaN: none, which compares false): a certificate needs every candidate
/// within the final radius, so a dropped one within it sends the point to the full double
/// search.
template <typename T, int N>
struct NearCandidates {
    int32_t slot[N];
    T q[N];
    int count = 0;
    T dropped = T(NAN);

    SDF_CPU_GPU SDF_INLINE void offer(int32_t s, T value) {
        if (count < N) {
            slot[count] = s;
            q[count] = value;
            ++count;
            return;
        }
        int worst = 0;
        for (int i = 1; i < N; ++i) worst = q[i] > q[worst] ? i : worst;
        if (value < q[worst]) {
            dropped = dropped < q[worst] ? dropped : q[worst];  // NaN < x is false
            slot[worst] = s;
            q[worst] = value;
        } else {
            dropped = dropped < value ? dropped : value;
        }
    }
};

/// Candidates a certified search keeps per point.
constexpr int kNearCandidates = 8;

/// What re-ranking found for one point.
struct Rerank {
    int32_t slot = -1;     ///< the double search's winner
    bool reranked = false; ///< double evaluations were needed (more than one candidate)
    bool overflow = false; ///< a dropped candidate was within the radius: slot is not set,
                           ///< run the full double search (seeded with the float winner)
};

/// The double search's winner among the float winner `winner` and the `count` candidates
/// (slots, float Q) within `radius`: Q on PackedTriangle<double> at the exact point, ties by
/// triangle index (`index_of(slot)`, the tie rule wins_tie). `dropped` is the smallest float
/// Q of a candidate that was not kept (NaN: none).
template <typename T, typename IndexOf>
SDF_CPU_GPU Rerank rerank_in_double(const PackedTriangle<double>* packed_double, IndexOf index_of, double px, double py,
                                    double pz, int32_t winner, T radius, const int32_t* slot, const T* q, int count,
                                    T dropped) {
    Rerank r;
    if (dropped <= radius) {
        r.overflow = true;
        return r;
    }
    int others = 0;
    for (int i = 0; i < count; ++i) others += int(slot[i] != winner && q[i] <= radius);
    r.slot = winner;
    if (others == 0) return r;
    r.reranked = true;
    double best = squared_distance(packed_double[winner], px, py, pz);
    int32_t best_index = index_of(winner);
    for (int i = 0; i < count; ++i) {
        if (slot[i] == winner || !(q[i] <= radius)) continue;
        const double d = squared_distance(packed_double[slot[i]], px, py, pz);
        const int32_t index = index_of(slot[i]);
        if (d < best || (d == best && index < best_index)) {
            best = d;
            best_index = index;
            r.slot = slot[i];
        }
    }
    return r;
}

template <typename T, int N, typename IndexOf>
SDF_CPU_GPU SDF_INLINE Rerank rerank_in_double(const PackedTriangle<double>* packed_double, IndexOf index_of, double px,
                                               double py, double pz, int32_t winner, T radius,
                                               const NearCandidates<T, N>& c) {
    return rerank_in_double(packed_double, index_of, px, py, pz, winner, radius, c.slot, c.q, c.count, c.dropped);
}

}  // namespace sdf
