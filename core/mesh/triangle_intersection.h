/// @file triangle_intersection.h
/// @brief Whether two triangles of one mesh intersect anywhere other than where the mesh's
/// connectivity says they meet: the predicate of the self-intersection check.
///
/// Two non-coplanar triangles intersect iff an edge of one meets the other (the ends of
/// their common segment on the planes' line lie on edges); a segment meets a triangle iff
/// its ends are not strictly on one side of the plane and the three orientations of the
/// segment's line against the triangle's edges agree (Pluecker). Coplanar pairs are
/// tested in the plane of projection that drops the normal's largest axis. The signs are
/// 3x3 determinants in double ("exact enough": a configuration within rounding of touching
/// may be called either way). Triangles that share vertices (by id) are judged with that
/// knowledge, as CGAL's self-intersection test does:
///   - 3 shared: the same triangle twice, which counts as intersecting;
///   - 2 shared (an edge): intersecting only if coplanar and folded onto each other
///     (both third vertices on the same side of the edge);
///   - 1 shared (a corner v): intersecting iff the edge opposite v of either triangle meets
///     the other triangle (the common segment starts at v and ends on such an edge).
#pragma once

#include "kernels/core/vec3.h"

namespace sdf {

/// Triangles (a0 a1 a2) and (b0 b1 b2) with vertex ids ia and ib; true when they meet
/// anywhere besides their shared vertices and edge.
bool triangles_intersect(const Vec3d a[3], const Int3& ia, const Vec3d b[3], const Int3& ib);

/// The closed segment pq meets the closed triangle (t0 t1 t2).
bool segment_meets_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& t0, const Vec3d& t1, const Vec3d& t2);

}  // namespace sdf
