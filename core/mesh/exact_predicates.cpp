// The only translation unit that includes CGAL (exact_predicates.h says why).
#include "core/mesh/exact_predicates.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

namespace sdf::exact {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;

Point point(const Vec3d& p) { return {p.x, p.y, p.z}; }

int sign_of(CGAL::Sign s) { return s == CGAL::POSITIVE ? 1 : (s == CGAL::NEGATIVE ? -1 : 0); }

}  // namespace

int orientation(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
    return sign_of(CGAL::orientation(point(a), point(b), point(c), point(d)));
}

bool collinear(const Vec3d& a, const Vec3d& b, const Vec3d& c) { return CGAL::collinear(point(a), point(b), point(c)); }

int coplanar_orientation(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
    return sign_of(CGAL::coplanar_orientation(point(a), point(b), point(c), point(d)));
}

bool segment_meets_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& t0, const Vec3d& t1, const Vec3d& t2) {
    return CGAL::do_intersect(Kernel::Segment_3(point(p), point(q)), Kernel::Triangle_3(point(t0), point(t1), point(t2)));
}

bool triangles_meet(const Vec3d a[3], const Vec3d b[3]) {
    return CGAL::do_intersect(Kernel::Triangle_3(point(a[0]), point(a[1]), point(a[2])),
                              Kernel::Triangle_3(point(b[0]), point(b[1]), point(b[2])));
}

}  // namespace sdf::exact
