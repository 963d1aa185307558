#include "core/mesh/triangle_intersection.h"

#include <cmath>

namespace sdf {
namespace {

/// Sign of det[b - a, c - a, d - a]: which side of plane abc the point d is on.
int orient3d(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
    const double det = dot(b - a, cross(c - a, d - a));
    return (det > 0) - (det < 0);
}

struct P2 {
    double x, y;
};

int orient2d(const P2& a, const P2& b, const P2& c) {
    const double det = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    return (det > 0) - (det < 0);
}

/// Drops the axis where the plane's normal is largest (the projection keeps areas nonzero).
struct Projection {
    int u = 0, v = 1;
    explicit Projection(const Vec3d& normal) {
        const Vec3d n{std::abs(normal.x), std::abs(normal.y), std::abs(normal.z)};
        const int drop = n.x >= n.y && n.x >= n.z ? 0 : (n.y >= n.z ? 1 : 2);
        u = (drop + 1) % 3;
        v = (drop + 2) % 3;
    }
    P2 operator()(const Vec3d& p) const { return {p[u], p[v]}; }
};

bool on_segment_2d(const P2& a, const P2& b, const P2& p) {  // p collinear with ab
    return std::fmin(a.x, b.x) <= p.x && p.x <= std::fmax(a.x, b.x) && std::fmin(a.y, b.y) <= p.y && p.y <= std::fmax(a.y, b.y);
}

bool segments_meet_2d(const P2& p, const P2& q, const P2& a, const P2& b) {
    const int o1 = orient2d(p, q, a), o2 = orient2d(p, q, b), o3 = orient2d(a, b, p), o4 = orient2d(a, b, q);
    if (o1 * o2 < 0 && o3 * o4 < 0) return true;
    return (o1 == 0 && on_segment_2d(p, q, a)) || (o2 == 0 && on_segment_2d(p, q, b)) ||
           (o3 == 0 && on_segment_2d(a, b, p)) || (o4 == 0 && on_segment_2d(a, b, q));
}

bool point_in_triangle_2d(const P2& p, const P2& a, const P2& b, const P2& c) {
    const int o1 = orient2d(a, b, p), o2 = orient2d(b, c, p), o3 = orient2d(c, a, p);
    return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

bool coplanar_segment_meets_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& t0, const Vec3d& t1, const Vec3d& t2) {
    const Projection to2d(cross(t1 - t0, t2 - t0));
    const P2 a = to2d(t0), b = to2d(t1), c = to2d(t2), p2 = to2d(p), q2 = to2d(q);
    return point_in_triangle_2d(p2, a, b, c) || point_in_triangle_2d(q2, a, b, c) || segments_meet_2d(p2, q2, a, b) ||
           segments_meet_2d(p2, q2, b, c) || segments_meet_2d(p2, q2, c, a);
}

bool any_edge_meets(const Vec3d a[3], const Vec3d b[3]) {
    for (int e = 0; e < 3; ++e)
        if (segment_meets_triangle(a[e], a[(e + 1) % 3], b[0], b[1], b[2])) return true;
    return false;
}

/// Triangles sharing the edge (s0, s1) with third vertices x (first) and y (second).
bool folded_over_shared_edge(const Vec3d& s0, const Vec3d& s1, const Vec3d& x, const Vec3d& y) {
    if (orient3d(s0, s1, x, y) != 0) return false;  // not coplanar: they meet only along the edge
    const Projection to2d(cross(s1 - s0, x - s0));
    const P2 a = to2d(s0), b = to2d(s1);
    return orient2d(a, b, to2d(x)) * orient2d(a, b, to2d(y)) > 0;
}

}  // namespace

bool segment_meets_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& t0, const Vec3d& t1, const Vec3d& t2) {
    const int op = orient3d(t0, t1, t2, p), oq = orient3d(t0, t1, t2, q);
    if (op * oq > 0) return false;
    if (op == 0 && oq == 0) return coplanar_segment_meets_triangle(p, q, t0, t1, t2);
    const int s0 = orient3d(p, q, t0, t1), s1 = orient3d(p, q, t1, t2), s2 = orient3d(p, q, t2, t0);
    return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

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
        return segment_meets_triangle(a[(i + 1) % 3], a[(i + 2) % 3], b[0], b[1], b[2]) ||
               segment_meets_triangle(b[(j + 1) % 3], b[(j + 2) % 3], a[0], a[1], a[2]);
    }
    return any_edge_meets(a, b) || any_edge_meets(b, a);
}

}  // namespace sdf
