/// @file triangle_mesh.h
/// @brief A triangle soup as loaded or generated: positions and vertex-id triples, nothing else.
///
/// This is the adapter boundary (OpenVDB's MeshDataAdapter): file formats stop at the loader,
/// everything downstream sees a TriangleMesh and then a PreparedMesh.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/bounds3.h"
#include "kernels/core/vec3.h"

namespace sdf {

/// What triangulating a file's polygon faces found (polygon_triangulation.h).
struct PolygonStats {
    int64_t polygons = 0;            ///< faces of more than 3 corners
    int64_t non_planar = 0;          ///< of those, with a corner off the best-fit plane (kNonPlanarTolerance)
    double max_non_planarity = 0.0;  ///< largest corner distance from the plane / polygon size, over all
    int64_t not_simple = 0;          ///< crossing themselves or without area in their plane
};

struct TriangleMesh {
    std::string name;              ///< short name for reports ("dragon", "sphere")
    std::string source;            ///< file path or procedural description
    std::string content_sha256;    ///< of the file's bytes, or of the generated geometry
    std::vector<Vec3d> vertices;
    std::vector<Int3> triangles;   ///< in file order (polygons by polygon_triangulation.h)
    PolygonStats polygon_stats;    ///< of the file's faces of more than 3 corners
};

/// Axis-aligned bounds of the vertices referenced by triangles.
Bounds3 triangle_bounds(const std::vector<Vec3d>& vertices, const std::vector<Int3>& triangles);

/// SHA-256 over the binary vertex and index arrays (for meshes without a file).
std::string geometry_sha256(const TriangleMesh& mesh);

}  // namespace sdf
