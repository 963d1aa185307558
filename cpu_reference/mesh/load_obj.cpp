#include "cpu_reference/mesh/load_obj.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "cpu_reference/mesh/sha256.h"

namespace sdf {
namespace {

/// 1-based line number of the n-th (0-based) `v` line, for error messages.
int line_of_vertex(const std::string& path, size_t n) {
    std::ifstream in(path);
    std::string line;
    size_t seen = 0;
    for (int number = 1; std::getline(in, line); ++number) {
        size_t p = line.find_first_not_of(" \t");
        if (p != std::string::npos && line.compare(p, 2, "v ") == 0 && seen++ == n) return number;
    }
    return -1;
}

std::string stem_of(const std::string& path) { return std::filesystem::path(path).stem().string(); }

}  // namespace

TriangleMesh load_obj(const std::string& path) {
    if (!std::filesystem::is_regular_file(path))
        throw std::runtime_error(path + ": mesh file not found");

    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config))
        throw std::runtime_error(path + ": cannot parse OBJ: " + reader.Error());

    TriangleMesh mesh;
    mesh.name = stem_of(path);
    mesh.source = path;
    const auto& v = reader.GetAttrib().vertices;
    mesh.vertices.reserve(v.size() / 3);
    for (size_t i = 0; i + 2 < v.size(); i += 3) {
        const Vec3d p{double(v[i]), double(v[i + 1]), double(v[i + 2])};
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
            std::ostringstream msg;
            msg << path << ":" << line_of_vertex(path, i / 3) << ": vertex " << i / 3
                << " has a non-finite coordinate (" << p.x << " " << p.y << " " << p.z
                << "); expected three finite numbers";
            throw std::runtime_error(msg.str());
        }
        mesh.vertices.push_back(p);
    }

    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        const auto& faces = shape.mesh.num_face_vertices;
        size_t offset = 0;
        for (size_t f = 0; f < faces.size(); ++f) {
            const int n = faces[f];
            if (n == 3) {
                Int3 t{shape.mesh.indices[offset].vertex_index, shape.mesh.indices[offset + 1].vertex_index,
                       shape.mesh.indices[offset + 2].vertex_index};
                for (int k = 0; k < 3; ++k)
                    if (t[k] < 0 || size_t(t[k]) >= mesh.vertices.size())
                        throw std::runtime_error(path + ": face " + std::to_string(mesh.triangles.size()) +
                                                 " refers to vertex " + std::to_string(t[k] + 1) +
                                                 ", but the file has " +
                                                 std::to_string(mesh.vertices.size()) + " vertices");
                mesh.triangles.push_back(t);
            }
            offset += size_t(n);
        }
    }
    if (mesh.triangles.empty())
        throw std::runtime_error(path + ": no triangles found (expected `f` lines with 3 or more vertices)");

    mesh.content_sha256 = sha256_of_file(path);
    return mesh;
}

}  // namespace sdf
