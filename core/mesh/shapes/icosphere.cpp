#include <cmath>
#include <map>
#include <sstream>

#include "core/mesh/shapes/procedural_shapes.h"

namespace sdf {

TriangleMesh make_icosphere(int subdivisions, double radius, Vec3d center) {
    // The 12 vertices of an icosahedron: cyclic permutations of (0, +-1, +-phi).
    const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3d> v = {{-1, phi, 0}, {1, phi, 0},  {-1, -phi, 0}, {1, -phi, 0},
                            {0, -1, phi}, {0, 1, phi},  {0, -1, -phi}, {0, 1, -phi},
                            {phi, 0, -1}, {phi, 0, 1},  {-phi, 0, -1}, {-phi, 0, 1}};
    std::vector<Int3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                           {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                           {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                           {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (Vec3d& p : v) p = normalize_or_zero(p);

    // Each subdivision splits a triangle into 4 through its edge midpoints (shared per edge).
    for (int level = 0; level < subdivisions; ++level) {
        std::map<std::pair<int, int>, int> midpoint;
        auto mid = [&](int a, int b) {
            auto key = std::make_pair(std::min(a, b), std::max(a, b));
            auto it = midpoint.find(key);
            if (it != midpoint.end()) return it->second;
            v.push_back(normalize_or_zero((v[size_t(a)] + v[size_t(b)]) * 0.5));
            return midpoint[key] = int(v.size() - 1);
        };
        std::vector<Int3> next;
        next.reserve(f.size() * 4);
        for (const Int3& t : f) {
            const int ab = mid(t.x, t.y), bc = mid(t.y, t.z), ca = mid(t.z, t.x);
            next.push_back({t.x, ab, ca});
            next.push_back({t.y, bc, ab});
            next.push_back({t.z, ca, bc});
            next.push_back({ab, bc, ca});
        }
        f.swap(next);
    }

    TriangleMesh mesh;
    mesh.name = "sphere";
    std::ostringstream src;
    src << "procedural icosphere(subdivisions=" << subdivisions << ", radius=" << radius << ")";
    mesh.source = src.str();
    for (const Vec3d& p : v) mesh.vertices.push_back(center + p * radius);
    mesh.triangles = f;
    mesh.content_sha256 = geometry_sha256(mesh);
    return mesh;
}

}  // namespace sdf
