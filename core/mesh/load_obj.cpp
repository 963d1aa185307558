#include "core/mesh/load_obj.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/mesh/sha256.h"

namespace sdf {
namespace {

/// tinyobjloader reads unparsable numbers ("nan", "abc") as 0 without a word, and rounds
/// about half of all decimal coordinates 1 to 3 ulp away from the nearest double (its own
/// mantissa-times-power parser; measured on the project's meshes). So every `v` line is
/// read here with strtod (correctly rounded): three finite numbers, or an error naming the
/// line; these positions replace tinyobjloader's.
std::vector<Vec3d> read_vertex_lines(std::istream& in, const std::string& path) {
    std::vector<Vec3d> vertices;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        std::istringstream ss(line);
        std::string tag;
        if (!(ss >> tag) || tag != "v") continue;
        Vec3d p;
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
            p[k] = value;
        }
        vertices.push_back(p);
    }
    return vertices;
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

/// The mesh tinyobjloader parsed, with the index checks of load_obj().
TriangleMesh mesh_from_reader(const tinyobj::ObjReader& reader, std::vector<Vec3d> vertices, const std::string& path) {
    reject_dropped_faces(path, reader.Warning());

    TriangleMesh mesh;
    mesh.name = stem_of(path);
    mesh.source = path;
    if (reader.GetAttrib().vertices.size() != 3 * vertices.size())
        throw std::runtime_error(path + ": tinyobjloader found " + std::to_string(reader.GetAttrib().vertices.size() / 3) +
                                 " vertices but the file has " + std::to_string(vertices.size()) + " `v` lines");
    mesh.vertices = std::move(vertices);

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
    return mesh;
}

tinyobj::ObjReaderConfig triangulating_config() {
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    return config;
}

}  // namespace

TriangleMesh load_obj(const std::string& path) {
    if (!std::filesystem::is_regular_file(path))
        throw std::runtime_error(path + ": mesh file not found");

    std::ifstream in(path);
    std::vector<Vec3d> vertices = read_vertex_lines(in, path);
    tinyobj::ObjReader reader;
    if (!reader.ParseFromFile(path, triangulating_config()))
        throw std::runtime_error(path + ": cannot parse OBJ: " + reader.Error());
    TriangleMesh mesh = mesh_from_reader(reader, std::move(vertices), path);
    mesh.content_sha256 = sha256_of_file(path);
    return mesh;
}

TriangleMesh load_obj_text(const std::string& text, const std::string& path) {
    std::istringstream in(text);
    std::vector<Vec3d> vertices = read_vertex_lines(in, path);
    tinyobj::ObjReader reader;
    if (!reader.ParseFromString(text, "", triangulating_config()))
        throw std::runtime_error(path + ": cannot parse OBJ: " + reader.Error());
    return mesh_from_reader(reader, std::move(vertices), path);
}

}  // namespace sdf
