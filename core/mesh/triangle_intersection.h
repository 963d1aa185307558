/// @file triangle_intersection.h
/// @brief Whether two triangles of one mesh intersect anywhere other than where the mesh's
/// connectivity says they meet: the predicate of the self-intersection check.
///
/// The rules are those of CGAL's Polygon_mesh_processing::self_intersections (its
/// do_faces_intersect), evaluated with exact predicates (exact_predicates.h), so that the
/// counts equal CGAL's: triangles are closed sets, and those sharing vertices (by id) are
/// judged with that knowledge:
///   - 3 shared: the same triangle twice, which counts as intersecting;
///   - 2 shared (an edge): intersecting only if the four points are coplanar and the third
///     vertices lie on the same side of the edge (folded onto each other);
///   - 1 shared (a corner v): intersecting iff the edge opposite v of either triangle meets
///     the other triangle (their common part is more than v);
///   - none: intersecting iff the closed triangles have a common point, so a vertex on the
///     other's face or edge (a T-junction) counts, as in CGAL.
/// Both triangles must be non-degenerate (prepare_mesh drops collinear ones).
#pragma once

#include "kernels/core/vec3.h"

namespace sdf {

/// Triangles (a0 a1 a2) and (b0 b1 b2) with vertex ids ia and ib; true when they meet
/// anywhere besides their shared vertices and edge.
bool triangles_intersect(const Vec3d a[3], const Int3& ia, const Vec3d b[3], const Int3& ib);

}  // namespace sdf
