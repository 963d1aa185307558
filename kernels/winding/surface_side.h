/// @file surface_side.h
/// @brief The exact side of a point from one triangle of a closed mesh and the triangles a
/// short segment crosses: the certified sign's first stage, which decides most points near
/// the surface, where the tree's far field would need many refinements. Host and device.
///
/// On a closed, consistently oriented mesh the generalized winding number w is an integer off
/// the surface, constant on each connected region of the complement, and one larger behind a
/// triangle's interior than in front of it (its solid angle jumps by 4 pi across it). Take a
/// triangle T whose interior no other triangle meets (no intersecting pair), its centroid y
/// and a point p. Walking from p to y, w changes only where the segment crosses a triangle U,
/// by +1 from U's front to its back; just before y it is the winding number beside T on p's
/// side. So
///   w(p) = front_winding[T] + (p behind T) + sum over U crossed by (p, y) of (p behind U ? +1 : -1),
///   inside  <=>  w(p) >= 1  (w > 1/2),
/// where front_winding[T] is the winding number in front of T: one certified evaluation per
/// edge-connected component of such triangles (core/winding/surface_sides.h).
///
/// Every term is decided by orientation determinants of the input doubles with rigorous
/// bounds (kernels/core/filtered_orientation.h); the centroid enters as a sum of three of
/// them, never as rounded coordinates. Nothing depends on T being the closest triangle: any T
/// gives the exact w. The closest one (the search's; where it is in an intersecting pair, the
/// nearest triangle across edges that is not, its stand-in) makes the segment short, so the
/// tree (the winding BVH's boxes) hands it few candidates. Where any determinant is undecided (p on
/// a triangle's plane, the segment through an edge) the point takes the ladder
/// (certified_winding.h); so do points within `min_distance` of the surface, where the
/// ladder's tie rule holds, and points with no triangle. Where a certified search hands on
/// its candidates, nearest_side() decides first from them alone, with no walk of the tree.
#pragma once

#include <cmath>
#include <cstdint>

#include "kernels/core/filtered_orientation.h"
#include "kernels/core/vec3.h"
#include "kernels/winding/fast_winding_number.h"

namespace sdf {

constexpr int8_t kSurfaceSideUnknown = INT8_MIN;

/// Plain pointers to a mesh's table (host or device); no table (front_winding null): off.
struct SurfaceSideView {
    const int8_t* front_winding = nullptr;  ///< per prepared triangle, or kSurfaceSideUnknown
    /// Per prepared triangle: the triangle whose centroid the segment runs to (itself when
    /// its front winding number is known; else the nearest known one across edges), or -1.
    const int32_t* stand_in = nullptr;
    double min_distance = 0;               ///< |d| at or below this: the ladder decides
};

/// A point y of T's open interior as positive integer weights of its corners,
/// y = (k0 t0 + k1 t1 + k2 t2) / (k0 + k1 + k2): the centroid (1, 1, 1), or a point near p's
/// closest point (nearest_side). y enters the determinants, which are affine in each point,
/// as the weighted sum of three, never as rounded coordinates.
struct InteriorPoint {
    double k[3] = {1.0, 1.0, 1.0};
};

/// k0 a + k1 b + k2 c with its rounding (three products, two additions) added to the bound.
SDF_CPU_GPU SDF_INLINE BoundedValue weighted_sum(const InteriorPoint& y, const BoundedValue& a, const BoundedValue& b,
                                                 const BoundedValue& c) {
    constexpr double eps = 1.1102230246251565404e-16;
    const double ka = y.k[0] * a.value, kb = y.k[1] * b.value, kc = y.k[2] * c.value;
    BoundedValue r;
    r.value = (ka + kb) + kc;
    r.bound = (y.k[0] * a.bound + y.k[1] * b.bound + y.k[2] * c.bound + 3.0 * eps * (fabs(ka) + fabs(kb) + fabs(kc))) * (1.0 + 8.0 * eps);
    return r;
}

/// The sign of det(a, b, c, y) for y in T (the weighted sum of three).
SDF_CPU_GPU SDF_INLINE int interior_orientation(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d t[3], const InteriorPoint& y) {
    return decided_sign(weighted_sum(y, orientation_det(a, b, c, t[0]), orientation_det(a, b, c, t[1]), orientation_det(a, b, c, t[2])));
}

/// The sign of det(p, y, a, b) for y in T: which side of the line p y the edge a b passes.
SDF_CPU_GPU SDF_INLINE int line_orientation(const Vec3d& p, const Vec3d t[3], const InteriorPoint& y, const Vec3d& a, const Vec3d& b) {
    return decided_sign(weighted_sum(y, orientation_det(p, t[0], a, b), orientation_det(p, t[1], a, b), orientation_det(p, t[2], a, b)));
}

/// A point y of T's interior known by rounded coordinates `at` within `radius` of it: one
/// determinant with y's rounding added to its bound (at most the determinant's gradient in
/// y, bounded by a product of lengths, times the radius) instead of a sum of three. Every
/// sign decided so holds for every point of the ball, y among them.
struct RoundedInteriorPoint {
    Vec3d at;
    double radius = 0;
};

/// |v|_1 >= |v|, no square root.
SDF_CPU_GPU SDF_INLINE double l1_norm(const Vec3d& v) { return fabs(v.x) + fabs(v.y) + fabs(v.z); }

/// |d det(a, b, c, y) / dy| = |(b - a) x (c - a)| <= |b - a|_1 |c - a|_1, rounded up.
SDF_CPU_GPU SDF_INLINE int interior_orientation(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d*,
                                                const RoundedInteriorPoint& y) {
    BoundedValue d = orientation_det(a, b, c, y.at);
    d.bound += l1_norm(b - a) * l1_norm(c - a) * y.radius * (1.0 + 0x1p-40);
    return decided_sign(d);
}

/// |d det(p, y, a, b) / dy| = |(p - b) x (a - b)| <= |p - b|_1 |a - b|_1, rounded up.
SDF_CPU_GPU SDF_INLINE int line_orientation(const Vec3d& p, const Vec3d*, const RoundedInteriorPoint& y, const Vec3d& a,
                                            const Vec3d& b) {
    BoundedValue d = orientation_det(p, y.at, a, b);
    d.bound += l1_norm(p - b) * l1_norm(a - b) * y.radius * (1.0 + 0x1p-40);
    return decided_sign(d);
}

/// Adds to `change` what crossing triangle u (corners u0 u1 u2, not T) on the way from p to
/// the point y of T's interior adds to w(p) - w(beside T): +1 when p is behind u, -1 in
/// front, 0 when the segment misses it. False when the determinants do not decide it. T's
/// interior meets no other triangle, so y lies on no u.
template <typename Y>
SDF_CPU_GPU inline bool add_crossing(const Vec3d& p, const Vec3d t[3], const Y& y, const Vec3d& u0, const Vec3d& u1,
                                     const Vec3d& u2, int& change) {
    // The segment p y crosses u iff the line p y passes its three edges on one side and p
    // and y lie on opposite sides of u's plane; the cheapest refutations first (two edges
    // on opposite sides miss u, whatever the third; then the plane).
    const int e0 = line_orientation(p, t, y, u0, u1), e1 = line_orientation(p, t, y, u1, u2);
    if (e0 * e1 < 0) return true;
    const int side_p = decided_sign(orientation_det(u0, u1, u2, p));
    const int side_y = interior_orientation(u0, u1, u2, t, y);
    if (side_p != 0 && side_p == side_y) return true;  // both strictly on one side of u's plane
    const int e2 = line_orientation(p, t, y, u2, u0);
    const bool positive = e0 > 0 || e1 > 0 || e2 > 0, negative = e0 < 0 || e1 < 0 || e2 < 0;
    if (positive && negative) return true;  // the line misses u
    // A crossing through u's interior, or a case the determinants leave open (an edge, a
    // corner, p on u's plane): only the first is decided.
    if (side_p == 0 || side_y == 0 || e0 == 0 || e1 == 0 || e2 == 0) return false;
    change += side_p > 0 ? 1 : -1;
    return true;
}

/// Whether the segment from p along dir = 1 / inv (t in [0, 1]) may meet the box [lo, hi]
/// grown by `slack`: conservative (the slack covers the rounding of dir, of its inverse and
/// of the slab parameters, a few ulps of the coordinates). A zero component of dir has an
/// infinite inverse, whose slab is all or nothing.
SDF_CPU_GPU SDF_INLINE bool segment_may_meet_box(const Vec3d& p, const Vec3d& inv, double slack, const Vec3d& lo,
                                                 const Vec3d& hi) {
    double t0 = 0.0, t1 = 1.0;
    for (int k = 0; k < 3; ++k) {
        const double a = lo[k] - slack - p[k], b = hi[k] + slack - p[k];
        if (inv[k] == INFINITY || inv[k] == -INFINITY) {  // parallel to the slab
            if (a > 0.0 || b < 0.0) return false;
            continue;
        }
        const double ta = a * inv[k], tb = b * inv[k];
        const double near = ta < tb ? ta : tb, far = ta < tb ? tb : ta;
        t0 = near > t0 ? near : t0;
        t1 = far < t1 ? far : t1;
    }
    return t0 <= t1;
}

/// w(p) - front_winding[T] - (p behind T) from the triangles the segment from p to T's
/// centroid crosses, found through the tree's boxes; false when a crossing is undecided.
SDF_CPU_GPU inline bool segment_winding_change(const WindingView<double>& v, const Vec3d& p, int triangle, const Vec3d t[3],
                                               int& change) {
    const Vec3d y = (t[0] + t[1] + t[2]) / 3.0;  // for the boxes only
    const Vec3d dir = y - p, inv(1.0 / dir.x, 1.0 / dir.y, 1.0 / dir.z);
    const double scale = fmax(v.scale, fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z))));
    const double slack = ldexp(scale, -40);
    change = 0;
    int32_t stack[kBvhMaxDepth + 1];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const BvhNode& n = v.nodes[stack[--top]];
        for (int c = 0; c < 2; ++c) {
            if (n.count[c] == 0 && n.ref[c] < 0) continue;  // an empty root child
            if (!segment_may_meet_box(p, inv, slack, Vec3d(n.min_x[c], n.min_y[c], n.min_z[c]), Vec3d(n.max_x[c], n.max_y[c], n.max_z[c])))
                continue;
            if (!bvh_child_is_leaf(n, c)) {
                SDF_DCHECK(top <= kBvhMaxDepth);
                stack[top++] = n.ref[c];
                continue;
            }
            for (int32_t slot = n.ref[c]; slot < n.ref[c] + n.count[c]; ++slot) {
                const int32_t u = v.triangle_index[slot];
                if (u == triangle) continue;
                const Int3 ui = v.triangles[u];
                const Vec3d u0 = v.vertices[ui.x], u1 = v.vertices[ui.y], u2 = v.vertices[ui.z];
                if (!segment_may_meet_box(p, inv, slack, component_min(u0, component_min(u1, u2)), component_max(u0, component_max(u1, u2))))
                    continue;  // most of a leaf's triangles: the determinants cost more than this
                if (!add_crossing(p, t, InteriorPoint{}, u0, u1, u2, change)) return false;
            }
        }
    }
    return true;
}

/// n . ((b - a) x (p - a)) for T's normal n = (t1 - t0) x (t2 - t0) and its edge a b, with a
/// bound on its rounding: positive when p lies on T's inner side of the plane through the
/// edge along n. Each of n and the cross product rounds a difference, a product and a
/// difference (4 roundings of their terms' magnitudes), the dot product 3 more on products
/// of them: at most gamma_11 of the same sum taken in magnitudes (Higham's bound), 16 u here
/// with its own rounding; products lost to underflow add at most 2^-1074 each, times the
/// other factor's size (2^-1070 of the sum, taken as kUnderflowAllowance).
SDF_CPU_GPU SDF_INLINE BoundedValue edge_prism_det(const Vec3d t[3], const Vec3d& a, const Vec3d& b, const Vec3d& p) {
    const Vec3d e0 = t[1] - t[0], e1 = t[2] - t[0], ab = b - a, ap = p - a;
    const Vec3d n = cross(e0, e1), g = cross(ab, ap);
    auto magnitude_cross = [](const Vec3d& u, const Vec3d& w) {
        return Vec3d(fabs(u.y * w.z) + fabs(u.z * w.y), fabs(u.z * w.x) + fabs(u.x * w.z), fabs(u.x * w.y) + fabs(u.y * w.x));
    };
    const Vec3d nm = magnitude_cross(e0, e1), gm = magnitude_cross(ab, ap);
    const double permanent = nm.x * gm.x + nm.y * gm.y + nm.z * gm.z;
    constexpr double eps = 1.1102230246251565404e-16;  // 2^-53
    BoundedValue r;
    r.value = n.x * g.x + n.y * g.y + n.z * g.z;
    r.bound = 16.0 * eps * permanent + kUnderflowAllowance * (1.0 + nm.x + nm.y + nm.z + gm.x + gm.y + gm.z);
    if (!(permanent < 1e300)) r.bound = INFINITY;
    return r;
}

/// Whether p's orthogonal projection onto T's plane lies strictly inside T, decided exactly
/// (false where the bounds do not decide it): then T's closest point to p is in T's open
/// interior, and p - (that point) is along T's normal.
SDF_CPU_GPU SDF_INLINE bool projects_inside(const Vec3d t[3], const Vec3d& p) {
    return decided_sign(edge_prism_det(t, t[0], t[1], p)) > 0 && decided_sign(edge_prism_det(t, t[1], t[2], p)) > 0 &&
           decided_sign(edge_prism_det(t, t[2], t[0], p)) > 0;
}

/// What a certified search knows beside its winner (search_certificate.h): the triangles it
/// could not rule out as nearer p than its winner (its candidates, the winner among them),
/// and a squared distance that every other triangle surely exceeds in exact arithmetic.
/// count 0: nothing known.
struct NearTriangles {
    const int32_t* triangle = nullptr;  ///< candidate k at triangle[k * stride]
    int count = 0;
    double beyond_squared = 0;
    int64_t stride = 1;
};

/// Weights of a point of T's open interior within about 2^-20 of T's size from `closest` (a
/// point of T, rounded), in units of 2^-20; false for a degenerate T.
SDF_CPU_GPU SDF_INLINE bool interior_point_near(const Vec3d t[3], const Vec3d& closest, InteriorPoint& y) {
    constexpr double kUnits = 1048576.0;  // 2^20
    const Vec3d e0 = t[1] - t[0], e1 = t[2] - t[0], c = closest - t[0];
    const double d00 = dot(e0, e0), d01 = dot(e0, e1), d11 = dot(e1, e1), d20 = dot(c, e0), d21 = dot(c, e1);
    const double denominator = d00 * d11 - d01 * d01;
    if (!(denominator > 0) || !(denominator < INFINITY)) return false;
    const double b1 = (d11 * d20 - d01 * d21) / denominator, b2 = (d00 * d21 - d01 * d20) / denominator;
    const double k1 = fmin(fmax(nearbyint(b1 * kUnits), 1.0), kUnits - 2.0);
    const double k2 = fmin(fmax(nearbyint(b2 * kUnits), 1.0), kUnits - 1.0 - k1);
    if (!(k1 >= 1.0) || !(k2 >= 1.0)) return false;  // NaN
    y.k[0] = kUnits - k1 - k2;
    y.k[1] = k1;
    y.k[2] = k2;
    return true;
}

/// The side of p from its nearest triangles alone, with no walk of the tree. T (`triangle`, a
/// search's winner, at `distance` from p, its closest point `closest`) must have a known
/// front winding number (its interior meets no other triangle).
///  - T the only candidate and p projecting inside T: let q be T's closest point to p; the
///    segment (p, q] meets no other triangle (one through a point x of it would lie at most
///    |p - x| <= |p - q| from p, nearer than T or as near; at q it would meet T's interior),
///    and beside T's interior on p's side w is one value: w(p) = front_winding[T] +
///    (p behind T).
///  - Otherwise a point y of T's interior next to `closest`: where |p - y| (rounded up) is
///    below sqrt(beyond_squared), every triangle that meets the segment p y lies nearer p
///    than that, so it is a candidate: the walk's formula (file comment) over the candidates
///    alone, with y for the centroid.
/// False where any of that is not decided: the caller then asks surface_side().
SDF_CPU_GPU inline bool nearest_side(const SurfaceSideView& s, const WindingView<double>& v, const Vec3d& p, int triangle,
                                     double distance, const Vec3d& closest, const NearTriangles& near, bool& inside) {
    if (s.front_winding == nullptr || triangle < 0 || near.count <= 0 || !(fabs(distance) > s.min_distance)) return false;
    const int8_t front = s.front_winding[triangle];
    if (front == kSurfaceSideUnknown) return false;
    const Int3 ti = v.triangles[triangle];
    const Vec3d t[3] = {v.vertices[ti.x], v.vertices[ti.y], v.vertices[ti.z]};
    const int behind = decided_sign(orientation_det(t[0], t[1], t[2], p));
    if (behind == 0) return false;
    const int beside = int(front) + (behind > 0 ? 1 : 0);
    if (near.count == 1 && projects_inside(t, p)) {
        inside = beside >= 1;
        return true;
    }
    InteriorPoint y;
    if (!interior_point_near(t, closest, y)) return false;
    // y's rounded coordinates: each off by at most 3 u of the largest |coordinate| of T
    // (three products, two sums; the division by a power of two exact), so |y - yr| <= 2^-50
    // of it; |p - y| rounded up from |p - yr| (a few u of itself) by that.
    const double units = y.k[0] + y.k[1] + y.k[2];
    const RoundedInteriorPoint yr{(t[0] * y.k[0] + t[1] * y.k[1] + t[2] * y.k[2]) / units,
                                  0x1p-50 * fmax(fmax(fmax(fabs(t[0].x), fabs(t[0].y)), fmax(fabs(t[0].z), fabs(t[1].x))),
                                                 fmax(fmax(fabs(t[1].y), fabs(t[1].z)), fmax(fmax(fabs(t[2].x), fabs(t[2].y)), fabs(t[2].z))))};
    const double reach = length(p - yr.at) * (1.0 + 0x1p-44) + yr.radius;
    if (!(reach * reach * (1.0 + 0x1p-44) < near.beyond_squared)) return false;
    int change = 0;
    for (int i = 0; i < near.count; ++i) {
        const int32_t u = near.triangle[i * near.stride];
        if (u == triangle) continue;
        const Int3 ui = v.triangles[u];
        if (!add_crossing(p, t, yr, v.vertices[ui.x], v.vertices[ui.y], v.vertices[ui.z], change)) return false;
    }
    inside = beside + change >= 1;
    return true;
}

/// Decides `inside` (w(p) > 1/2, exactly) from triangle `triangle` (the search's closest, at
/// distance `distance` from p) or its stand-in; false when the table cannot: no table, no
/// triangle, no stand-in, p within min_distance of the surface, or a determinant left
/// undecided.
SDF_CPU_GPU inline bool surface_side(const SurfaceSideView& s, const WindingView<double>& v, const Vec3d& p, int triangle,
                                     double distance, bool& inside) {
    if (s.front_winding == nullptr || triangle < 0 || !(fabs(distance) > s.min_distance)) return false;
    triangle = s.stand_in[triangle];
    if (triangle < 0) return false;
    const int8_t front = s.front_winding[triangle];
    const Int3 ti = v.triangles[triangle];
    const Vec3d t[3] = {v.vertices[ti.x], v.vertices[ti.y], v.vertices[ti.z]};
    const int behind = decided_sign(orientation_det(t[0], t[1], t[2], p));
    if (behind == 0) return false;
    int change = 0;
    if (!segment_winding_change(v, p, triangle, t, change)) return false;
    inside = int(front) + (behind > 0 ? 1 : 0) + change >= 1;
    return true;
}

}  // namespace sdf
