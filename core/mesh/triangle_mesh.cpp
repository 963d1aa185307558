#include "core/mesh/triangle_mesh.h"

#include "core/mesh/sha256.h"

namespace sdf {

Bounds3 triangle_bounds(const std::vector<Vec3d>& vertices, const std::vector<Int3>& triangles) {
    Bounds3 b;
    for (const Int3& t : triangles)
        for (int k = 0; k < 3; ++k) b.extend(vertices[size_t(t[k])]);
    return b;
}

std::string geometry_sha256(const TriangleMesh& mesh) {
    std::string bytes;
    bytes.append(reinterpret_cast<const char*>(mesh.vertices.data()), mesh.vertices.size() * sizeof(Vec3d));
    bytes.append(reinterpret_cast<const char*>(mesh.triangles.data()), mesh.triangles.size() * sizeof(Int3));
    return sha256_hex(bytes.data(), bytes.size());
}

}  // namespace sdf
