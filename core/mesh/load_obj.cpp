#include "core/mesh/load_obj.h"

#include <tiny_obj_loader.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/io/text_file.h"
#include "core/mesh/mesh_file_bytes.h"
#include "core/mesh/sha256.h"
#include "core/mesh/text_cursor.h"

namespace sdf {
namespace {

/// tinyobjloader reads unparsable numbers ("nan", "abc") as 0 without a word, and rounds
/// about half of all decimal coordinates 1 to 3 ulp away from the nearest double (its own
/// mantissa-times-power parser; measured on the project's meshes). So every `v` line is
/// read here with strtod (correctly rounded): three finite numbers, or an error naming the
/// line; these positions replace tinyobjloader's.
///
/// Its face indices are read with a 32-bit atoi: "1.5" reads as 1, 4294967297 wraps to 1,
/// both valid vertices. So every `f` line's vertex indices are checked here too: whole
/// decimal integers, not 0, negative ones (relative: -1 is the last vertex so far) within
/// the vertices before the line, positive ones within the file's vertices; an error quotes
/// the index as written and names the line.
std::vector<Vec3d> read_vertex_lines(std::istream& in, const std::string& path) {
    std::vector<Vec3d> vertices;
    std::string line;
    struct FaceReference {
        int line;
        int64_t index;
        std::string token;
    };
    std::vector<FaceReference> largest_positive;  // one entry: the largest positive index seen
    for (int number = 1; std::getline(in, line); ++number) {
        std::istringstream ss(line);
        std::string tag;
        if (!(ss >> tag)) continue;
        if (tag == "f") {
            std::string token;
            while (ss >> token) {
                const std::string_view index_part = std::string_view(token).substr(0, token.find('/'));
                int64_t index = 0;
                const auto fail = [&](const std::string& why) {
                    throw std::runtime_error(path + ":" + std::to_string(number) + ": face vertex " + sdf::quoted(token) +
                                             " " + why);
                };
                if (!parse_int(index_part, index)) fail("is not a whole number; expected a vertex index");
                if (index == 0) fail("is 0; OBJ indices start at 1 (or count back from -1)");
                if (index < 0 && -index > int64_t(vertices.size()))
                    fail("counts back further than the " + std::to_string(vertices.size()) +
                         " vertices before this line");
                if (index > 0 && (largest_positive.empty() || index > largest_positive[0].index))
                    largest_positive.assign(1, FaceReference{number, index, token});
            }
            continue;
        }
        if (tag != "v") continue;
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
        if (vertices.size() > size_t(std::numeric_limits<int>::max()))
            throw std::runtime_error(path + ":" + std::to_string(number) + ": more than " +
                                     std::to_string(std::numeric_limits<int>::max()) + " vertices");
    }
    if (!largest_positive.empty() && largest_positive[0].index > int64_t(vertices.size()))
        throw std::runtime_error(path + ":" + std::to_string(largest_positive[0].line) + ": face vertex " +
                                 sdf::quoted(largest_positive[0].token) + " refers to vertex " +
                                 std::to_string(largest_positive[0].index) + ", but the file has " +
                                 std::to_string(vertices.size()) + " vertices");
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
    TriangleMesh mesh = load_obj_text(read_text_file(path, "mesh file", kMaxMeshFileBytes), path);
    mesh.content_sha256 = sha256_of_file(path);
    return mesh;
}

TriangleMesh load_obj_text(const std::string& bytes, const std::string& path) {
    // A byte-order mark would glue itself to the first `v` and shift every index by one.
    reject_wide_encodings(bytes, path, "OBJ file");
    const std::string text(without_utf8_bom(bytes));
    std::istringstream in(text);
    std::vector<Vec3d> vertices = read_vertex_lines(in, path);
    tinyobj::ObjReader reader;
    if (!reader.ParseFromString(text, "", triangulating_config()))
        throw std::runtime_error(path + ": cannot parse OBJ: " + reader.Error());
    return mesh_from_reader(reader, std::move(vertices), path);
}

}  // namespace sdf
