/// @file triangle_mesh.h
/// @brief A triangle soup as loaded or generated: positions and vertex-id triples, nothing else.
///
/// This is the adapter boundary (OpenVDB's MeshDataAdapter): file formats stop at the loader,
/// everything downstream sees a TriangleMesh and then a PreparedMesh.
#pragma once

#include <string>
#include <vector>

#include "core/bounds3.h"
#include "kernels/core/vec3.h"

namespace sdf {

struct TriangleMesh {
    std::string name;              ///< short name for reports ("dragon", "sphere")
    std::string source;            ///< file path or procedural description
    std::string content_sha256;    ///< of the file's bytes, or of the generated geometry
    std::vector<Vec3d> vertices;
    std::vector<Int3> triangles;   ///< in file order (polygons triangulated as fans)
};

/// Axis-aligned bounds of the vertices referenced by triangles.
Bounds3 triangle_bounds(const std::vector<Vec3d>& vertices, const std::vector<Int3>& triangles);

/// SHA-256 over the binary vertex and index arrays (for meshes without a file).
std::string geometry_sha256(const TriangleMesh& mesh);

}  // namespace sdf
