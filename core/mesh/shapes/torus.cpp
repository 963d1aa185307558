#include <cmath>
#include <sstream>

#include "core/mesh/shapes/procedural_shapes.h"

namespace sdf {

TriangleMesh make_torus(double major_radius, double minor_radius, int major_segments, int minor_segments) {
    constexpr double kTwoPi = 6.28318530717958647692;
    TriangleMesh mesh;
    mesh.name = "torus";
    std::ostringstream src;
    src << "procedural torus(R=" << major_radius << ", r=" << minor_radius << ", segments=" << major_segments
        << "x" << minor_segments << ")";
    mesh.source = src.str();
    for (int i = 0; i < major_segments; ++i) {
        const double u = kTwoPi * i / major_segments;
        for (int j = 0; j < minor_segments; ++j) {
            const double v = kTwoPi * j / minor_segments;
            const double ring = major_radius + minor_radius * std::cos(v);
            mesh.vertices.push_back({ring * std::cos(u), ring * std::sin(u), minor_radius * std::sin(v)});
        }
    }
    auto id = [&](int i, int j) { return (i % major_segments) * minor_segments + (j % minor_segments); };
    for (int i = 0; i < major_segments; ++i)
        for (int j = 0; j < minor_segments; ++j) {
            // Quad (i,j)-(i+1,j)-(i+1,j+1)-(i,j+1) is counter-clockwise seen from outside.
            const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
            mesh.triangles.push_back({a, b, c});
            mesh.triangles.push_back({a, c, d});
        }
    mesh.content_sha256 = geometry_sha256(mesh);
    return mesh;
}

}  // namespace sdf
