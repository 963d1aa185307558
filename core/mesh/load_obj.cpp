#include "core/mesh/load_obj.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "core/mesh/sha256.h"

namespace sdf {
namespace {

/// tinyobjloader reads unparsable numbers ("nan", "abc") as 0 without a word, so every
/// `v` line is checked here first: three finite numbers, or an error naming the line.
void check_vertex_lines(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        std::istringstream ss(line);
        std::string tag;
        if (!(ss >> tag) || tag != "v") continue;
        for (int k = 0; k < 3; ++k) {
            std::string token;
            char* end = nullptr;
            const bool present = bool(ss >> token);
            const double value = present ? std::strtod(token.c_str(), &end) : 0.0;
            if (!present || end != token.c_str() + token.size() || !std::isfinite(value))
                throw std::runtime_error(path + ":" + std::to_string(number) + ": " +
                                         (present ? "non-finite or malformed vertex coordinate '" + token + "'"
                                                  : std::string("missing vertex coordinate")) +
                                         "; expected three finite numbers after 'v'");
        }
    }
}

/// tinyobjloader skips faces with fewer than 3 vertices or with invalid indices and only
/// warns; for distance fields a silently missing face changes the answer, so it is an error.
void reject_dropped_faces(const std::string& path, const std::string& warnings) {
    for (const char* fatal : {"Face with invalid vertex index", "Degenerated face"})
        if (warnings.find(fatal) != std::string::npos)
            throw std::runtime_error(path + ": " + fatal +
                                     " found (a face refers to a missing vertex or has fewer than 3 vertices)");
}

std::string stem_of(const std::string& path) { return std::filesystem::path(path).stem().string(); }

}  // namespace

TriangleMesh load_obj(const std::string& path) {
    if (!std::filesystem::is_regular_file(path))
        throw std::runtime_error(path + ": mesh file not found");

    check_vertex_lines(path);
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, config))
        throw std::runtime_error(path + ": cannot parse OBJ: " + reader.Error());
    reject_dropped_faces(path, reader.Warning());

    TriangleMesh mesh;
    mesh.name = stem_of(path);
    mesh.source = path;
    const auto& v = reader.GetAttrib().vertices;
    mesh.vertices.reserve(v.size() / 3);
    for (size_t i = 0; i + 2 < v.size(); i += 3) {
        const Vec3d p{double(v[i]), double(v[i + 1]), double(v[i + 2])};
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
