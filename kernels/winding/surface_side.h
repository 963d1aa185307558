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
/// ladder's tie rule holds, and points with no triangle.
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

/// The sign of det(a, b, c, y) for T's centroid y = (t0 + t1 + t2) / 3 (the sum of three).
SDF_CPU_GPU SDF_INLINE int centroid_orientation(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d t[3]) {
    return decided_sign(bounded_sum(orientation_det(a, b, c, t[0]), orientation_det(a, b, c, t[1]), orientation_det(a, b, c, t[2])));
}

/// The sign of det(p, y, a, b) for T's centroid y: which side of the line p y the edge a b
/// passes.
SDF_CPU_GPU SDF_INLINE int line_orientation(const Vec3d& p, const Vec3d t[3], const Vec3d& a, const Vec3d& b) {
    return decided_sign(bounded_sum(orientation_det(p, t[0], a, b), orientation_det(p, t[1], a, b), orientation_det(p, t[2], a, b)));
}

/// Adds to `change` what crossing triangle u (corners u0 u1 u2, not T) on the way from p to
/// T's centroid adds to w(p) - w(beside T): +1 when p is behind u, -1 in front, 0 when the
/// segment misses it. False when the determinants do not decide it. T's interior meets no
/// other triangle, so the centroid lies on no u.
SDF_CPU_GPU inline bool add_crossing(const Vec3d& p, const Vec3d t[3], const Vec3d& u0, const Vec3d& u1, const Vec3d& u2,
                                     int& change) {
    const int side_p = decided_sign(orientation_det(u0, u1, u2, p));
    const int side_y = centroid_orientation(u0, u1, u2, t);
    if (side_p != 0 && side_p == side_y) return true;  // both strictly on one side of u's plane
    // The line p y meets the closed triangle u iff it passes its three edges on one side.
    const int e0 = line_orientation(p, t, u0, u1), e1 = line_orientation(p, t, u1, u2), e2 = line_orientation(p, t, u2, u0);
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
                if (!add_crossing(p, t, u0, u1, u2, change)) return false;
            }
        }
    }
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
