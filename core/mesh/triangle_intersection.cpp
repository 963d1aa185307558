#include "core/mesh/triangle_intersection.h"

#include "core/mesh/exact_predicates.h"

namespace sdf {
namespace {

/// Triangles sharing the edge (s0, s1), with third vertices x (first) and y (second).
bool folded_over_shared_edge(const Vec3d& s0, const Vec3d& s1, const Vec3d& x, const Vec3d& y) {
    return exact::orientation(s0, s1, x, y) == 0 && exact::coplanar_orientation(s0, s1, x, y) > 0;
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
        return exact::segment_meets_triangle(b[(j + 1) % 3], b[(j + 2) % 3], a[0], a[1], a[2]) ||
               exact::segment_meets_triangle(a[(i + 1) % 3], a[(i + 2) % 3], b[0], b[1], b[2]);
    }
    return exact::triangles_meet(a, b);
}

}  // namespace sdf
