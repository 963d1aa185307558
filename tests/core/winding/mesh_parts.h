/// @file mesh_parts.h
/// @brief Several meshes as one (their triangles numbered on): the overlapping and nested
/// shells of the winding-number tests.
#pragma once

#include <vector>

#include "core/mesh/triangle_mesh.h"

namespace sdf::test {

inline TriangleMesh concatenated(const std::vector<TriangleMesh>& parts, const char* name = "parts") {
    TriangleMesh all;
    all.name = name;
    for (const TriangleMesh& m : parts) {
        const int first = int(all.vertices.size());
        all.vertices.insert(all.vertices.end(), m.vertices.begin(), m.vertices.end());
        for (const Int3& t : m.triangles) all.triangles.push_back({t.x + first, t.y + first, t.z + first});
    }
    return all;
}

}  // namespace sdf::test
