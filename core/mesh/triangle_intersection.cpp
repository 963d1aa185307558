#include "core/mesh/triangle_intersection.h"

#include <cmath>
#include <limits>

#include "core/mesh/exact_predicates.h"

namespace sdf {
namespace {

/// Triangles sharing the edge (s0, s1), with third vertices x (first) and y (second).
bool folded_over_shared_edge(const Vec3d& s0, const Vec3d& s1, const Vec3d& x, const Vec3d& y) {
    return exact::orientation(s0, s1, x, y) == 0 && exact::coplanar_orientation(s0, s1, x, y) > 0;
}

/// Which side of the plane through v with normal n the point x is on, when rounding cannot
/// change the answer: +1 or -1, else 0 (unknown). The bound covers the rounded difference
/// x - v and the rounded dot product (Higham's gamma_n, generously: 8 units of roundoff).
int certain_side(const Vec3d& n, const Vec3d& v, const Vec3d& x) {
    const Vec3d d = x - v;
    const double value = dot(n, d);
    const double bound = 8.0 * std::numeric_limits<double>::epsilon() *
                         (std::abs(n.x * d.x) + std::abs(n.y * d.y) + std::abs(n.z * d.z));
    if (std::abs(value) < 1e-280) return 0;  // where underflow could hide in the products
    return value > bound ? 1 : (value < -bound ? -1 : 0);
}

/// A certain "no" for triangles (v, a1, a2) and (v, b1, b2) that share only the corner v: a plane
/// through v with a1, a2 strictly on one side and b1, b2 strictly on the other leaves them only v
/// in common. The planes tried contain the mean normal and a direction between the two corners'
/// fans (the bisector of an a corner's and a b corner's directions), which finds one for the
/// disjoint triangles around a CAD fan's centre, where thousands of pairs share a vertex.
/// False means "not shown", and the exact test decides.
bool separated_at_shared_corner(const Vec3d& v, const Vec3d& a1, const Vec3d& a2, const Vec3d& b1, const Vec3d& b2) {
    const Vec3d na = normalize_or_zero(cross(a1 - v, a2 - v)), nb0 = normalize_or_zero(cross(b1 - v, b2 - v));
    const Vec3d nb = dot(na, nb0) < 0 ? -nb0 : nb0;
    const Vec3d normal = na + nb;
    if (!(dot(normal, normal) > 1e-12)) return false;  // a degenerate corner, or opposite normals
    const Vec3d ua[2] = {normalize_or_zero(a1 - v), normalize_or_zero(a2 - v)}, ub[2] = {normalize_or_zero(b1 - v), normalize_or_zero(b2 - v)};
    for (const Vec3d& p : ua)
        for (const Vec3d& q : ub) {
            const Vec3d n = cross(normal, p + q);
            const int s = certain_side(n, v, a1);
            if (s != 0 && certain_side(n, v, a2) == s && certain_side(n, v, b1) == -s && certain_side(n, v, b2) == -s) return true;
        }
    return false;
}

}  // namespace

bool triangles_intersect(const Vec3d a[3], const Int3& ia, const Vec3d b[3], const Int3& ib) {
    int shared = 0, a_at[3] = {-1, -1, -1};  // a_at[i]: corner of b equal to corner i of a
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (ia[i] == ib[j]) { a_at[i] = j; ++shared; }
    if (shared == 3) return true;
    if (shared == 2) {
        const int x = a_at[0] < 0 ? 0 : (a_at[1] < 0 ? 1 : 2);  // a's corner off the shared edge
        int y = 0;
        while (y == a_at[(x + 1) % 3] || y == a_at[(x + 2) % 3]) ++y;  // b's corner off it
        return folded_over_shared_edge(a[(x + 1) % 3], a[(x + 2) % 3], a[x], b[y]);
    }
    if (shared == 1) {
        const int i = a_at[0] >= 0 ? 0 : (a_at[1] >= 0 ? 1 : 2), j = a_at[i];
        if (separated_at_shared_corner(a[i], a[(i + 1) % 3], a[(i + 2) % 3], b[(j + 1) % 3], b[(j + 2) % 3])) return false;
        return exact::segment_meets_triangle(b[(j + 1) % 3], b[(j + 2) % 3], a[0], a[1], a[2]) ||
               exact::segment_meets_triangle(a[(i + 1) % 3], a[(i + 2) % 3], b[0], b[1], b[2]);
    }
    return exact::triangles_meet(a, b);
}

}  // namespace sdf
