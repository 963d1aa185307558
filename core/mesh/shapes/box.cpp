#include <sstream>

#include "core/mesh/shapes/procedural_shapes.h"

namespace sdf {

TriangleMesh make_box(Vec3d half_extent, Vec3d center) {
    TriangleMesh mesh;
    mesh.name = "box";
    std::ostringstream src;
    src << "procedural box(half_extent=" << half_extent.x << "," << half_extent.y << "," << half_extent.z << ")";
    mesh.source = src.str();
    // Corner c has coordinates (+-hx, +-hy, +-hz) with bit 0 -> x, bit 1 -> y, bit 2 -> z.
    for (int c = 0; c < 8; ++c)
        mesh.vertices.push_back(center + Vec3d{(c & 1) ? half_extent.x : -half_extent.x,
                                               (c & 2) ? half_extent.y : -half_extent.y,
                                               (c & 4) ? half_extent.z : -half_extent.z});
    // Two counter-clockwise (seen from outside) triangles per face.
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6},   // -z, +z
                             {0, 1, 5, 4}, {2, 6, 7, 3},   // -y, +y
                             {0, 4, 6, 2}, {1, 3, 7, 5}};  // -x, +x
    for (const auto& q : quads) {
        mesh.triangles.push_back({q[0], q[1], q[2]});
        mesh.triangles.push_back({q[0], q[2], q[3]});
    }
    mesh.content_sha256 = geometry_sha256(mesh);
    return mesh;
}

}  // namespace sdf
