/// @file self_intersections.h
/// @brief Triangle pairs of a prepared mesh that intersect other than along shared edges
/// and vertices: self-intersections within a shell, and overlaps between shells. Found by
/// descending the mesh's BVH (core/bvh/triangle_bvh.h) in pairs of children whose
/// boxes overlap, then testing the pairs of triangles whose own boxes overlap with
/// triangles_intersect() (exact predicates, CGAL's rules: the counts equal CGAL's
/// Polygon_mesh_processing::self_intersections).
#pragma once

#include <utility>
#include <vector>

#include "core/bvh/triangle_bvh.h"
#include "core/mesh/prepared_mesh.h"

namespace sdf {

struct SelfIntersections {
    std::vector<std::pair<int, int>> pairs;  ///< prepared-mesh triangle ids (first < second), sorted
    int within_shell = 0;                    ///< pairs whose triangles share a shell (edge-connected component)
    int between_shells = 0;                  ///< pairs from two different shells
    int overlapping_shell_pairs = 0;         ///< distinct pairs of shells that intersect
    double seconds = 0;
};

/// `shell_of[t]` is triangle t's edge-connected component (any ids; empty = one shell).
/// `threads` (0: all hardware threads) share the descent; the result does not depend on it.
SelfIntersections find_self_intersections(const PreparedMesh& mesh, const TriangleBvh& bvh,
                                          const std::vector<int>& shell_of = {}, int threads = 0);

}  // namespace sdf
