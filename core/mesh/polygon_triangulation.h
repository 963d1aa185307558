/// @file polygon_triangulation.h
/// @brief The one triangulation of polygon faces that every mesh reader uses (OBJ, PLY,
/// OFF, STL), so that a polygon gives the same triangles whatever format it came in.
///
/// The rule, for a face of n > 3 corners:
///  1. Corners at the position of the corner before them (cyclically) are dropped: they
///     would only make zero-length edges, and welding merges them anyway.
///  2. The polygon is projected onto the coordinate plane most nearly parallel to its
///     best-fit plane (the Newell normal's largest component decides; the projection keeps
///     the polygon's orientation). A non-planar polygon becomes a height field over that
///     plane, so its triangles cannot cross one another.
///  3. Ear clipping in that plane: a corner is an ear when it is strictly convex (so a
///     corner on the straight line of its neighbours, a "collinear corner", never is: it
///     stays a vertex of the triangles around it and no zero-area triangle or T-junction
///     appears) and no other corner lies inside or on its triangle. Among the ears, the
///     one with the shortest cut (prev, next) is clipped first; for a quad this is the
///     split along its shorter diagonal. Equal cuts go to the corner that comes first after
///     the face's first corner (which comes last), so a rectangle, or any polygon whose
///     cuts tie, becomes the fan from its first corner.
///  4. Each triangle keeps the polygon's orientation and starts at its corner that comes
///     first in the face; triangles come in clipping order.
/// A polygon with no ear left (it crosses itself in its plane, or has no area) is finished
/// by clipping its most convex corner, and counted.
///
/// Ear clipping (Meisters 1975) is a few dozen lines here and needs no dependency: no C++
/// earcut or polygon triangulator is packaged in Debian 12 apart from CGAL, whose
/// constrained Delaunay triangulation would bring Boost, GMP and MPFR for faces that
/// are mostly quads. Cost: the corners that are not convex sit in k-d trees, so an ear
/// test looks only at those its triangle may reach, and a corner is tested again only when
/// a neighbour is clipped or the corner that blocked it leaves (issue 38): O(n log n) in
/// practice (a 40,000-corner star or comb: a fraction of a second; the plain O(n r) scan
/// took 29 s), the same triangles as the plain scan. A polygon that crosses itself (corners
/// turning reflex as others are clipped, fallbacks when no ear is left) keeps that cost:
/// late reflex corners join trees of their own and the fallback's corner comes from an
/// ordered set (40,000 random corners: 0.23 s, 3.5 s before). A long clipping
/// stops on the calling thread's stop request (task_monitor.h: Ctrl-C in Python).
#pragma once

#include <vector>

#include "core/mesh/triangle_mesh.h"

namespace sdf {

/// A corner farther than this fraction of its polygon's size (bounding-box diagonal) from
/// the polygon's best-fit plane makes the polygon non-planar: then the choice of cuts
/// changes the surface, and the mesh report says so. Files written with 7 significant
/// digits stay below it.
constexpr double kNonPlanarTolerance = 1e-6;

/// Appends the triangles of the face `corners` (vertex ids into `vertices`, in the face's
/// order, at least 3) to `out`, and counts what it found in `stats`. A triangle is
/// appended as it is.
void triangulate_polygon(const std::vector<Vec3d>& vertices, const std::vector<int>& corners,
                         std::vector<Int3>& out, PolygonStats& stats);

/// Faces of a reader in file order, triangulated at the end (when every vertex is known).
struct PolygonList {
    std::vector<int> corners;  ///< every face's vertex ids, one face after the other
    std::vector<int> sizes;    ///< corners per face

    void add(const std::vector<int>& face) {
        corners.insert(corners.end(), face.begin(), face.end());
        sizes.push_back(int(face.size()));
    }
    /// Triangulates every face into mesh.triangles and mesh.polygon_stats.
    void triangulate_into(TriangleMesh& mesh) const;
};

}  // namespace sdf
