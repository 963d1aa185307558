#include "core/mesh/load_obj.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <istream>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <streambuf>
#include <string_view>
#include <stdexcept>
#include <vector>

#include "core/io/text_file.h"
#include "core/mesh/mesh_file_bytes.h"
#include "core/mesh/polygon_triangulation.h"
#include "core/mesh/sha256.h"
#include "core/mesh/text_cursor.h"

namespace sdf {
namespace {

/// tinyobjloader reads unparsable numbers ("nan", "abc") as 0 without a word, and rounds
/// about half of all decimal coordinates 1 to 3 ulp away from the nearest double (its own
/// mantissa-times-power parser; measured on the project's meshes). So every `v` line is
/// read here with strtod (correctly rounded): three finite numbers, or an error naming the
/// line; these positions replace tinyobjloader's. (std::from_chars: correctly rounded like
/// strtod, without its locale.)
///
/// Its face indices are read with a 32-bit atoi: "1.5" reads as 1, 4294967297 wraps to 1,
/// both valid vertices. So every `f` line's vertex indices are checked here too: whole
/// decimal integers, not 0, negative ones (relative: -1 is the last vertex so far) within
/// the vertices before the line, positive ones within the file's vertices; an error quotes
/// the index as written and names the line.
///
/// Debian's tinyobjloader (2.0.0rc10) also stores a face's corner count in an unsigned char:
/// a face of 256 corners reads as 0 corners, one of 300 as 44, while all its indices are
/// kept. So the corners of every `f` line are counted here too (`corner_counts`, in file
/// order), and tinyobjloader's flat index list is cut into faces by these counts.
struct ObjLines {
    std::vector<Vec3d> vertices;
    std::vector<int64_t> corner_counts;  ///< of each `f` line, in file order
};

ObjLines read_obj_lines(std::string_view text, const std::string& path) {
    ObjLines lines;
    std::vector<Vec3d>& vertices = lines.vertices;
    struct FaceReference {
        int line;
        int64_t index;
        std::string token;
    };
    std::vector<FaceReference> largest_positive;  // one entry: the largest positive index seen
    int number = 0;
    for (size_t at = 0; at < text.size();) {
        // A line ends at "\n", "\r\n" or a lone "\r" (classic Mac OS), as tinyobjloader reads it.
        const size_t end = std::min(text.find_first_of("\r\n", at), text.size());
        const size_t line_start = at;
        TextCursor ss(text.substr(at, end - at));
        at = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
        ++number;
        std::string_view tag;
        if (!ss.next(tag)) continue;
        if (tag == "f") {
            std::string_view token;
            // A face line as tinyobjloader sees one: "f" after spaces or tabs, then a space or tab.
            const std::string_view line = text.substr(line_start, end - line_start);
            const size_t after = size_t(tag.data() - line.data()) + 1;
            const bool face = line.find_first_not_of(" \t") == after - 1 && after < line.size() &&
                              (line[after] == ' ' || line[after] == '\t');
            int64_t* corners = face ? &lines.corner_counts.emplace_back(0) : nullptr;
            while (ss.next(token)) {
                if (corners) ++*corners;
                const std::string_view index_part = token.substr(0, token.find('/'));
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
                    largest_positive.assign(1, FaceReference{number, index, std::string(token)});
            }
            continue;
        }
        if (tag != "v") continue;
        Vec3d p;
        for (int k = 0; k < 3; ++k) {
            std::string_view token;
            const bool present = ss.next(token);
            double value = 0.0;
            if (!present || !parse_double(token, value) || !std::isfinite(value))
                throw std::runtime_error(path + ":" + std::to_string(number) + ": " +
                                         (present ? "non-finite or malformed vertex coordinate " + sdf::quoted(token)
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
    return lines;
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

/// Reads OBJ text in place: tinyobjloader's ParseFromString would copy the text into a
/// stringstream, one more copy of a file that may be gigabytes.
class MemoryStreamBuffer : public std::streambuf {
public:
    explicit MemoryStreamBuffer(std::string_view text) {
        char* begin = const_cast<char*>(text.data());  // read only: the get area is never written
        setg(begin, begin, begin + text.size());
    }
};

/// What tinyobjloader parsed, polygons left whole.
struct ParsedObj {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::string warnings;
};

/// The mesh tinyobjloader parsed, its faces cut by the corner counts of read_obj_lines()
/// (tinyobjloader's own counts are checked modulo 256), with the index checks of load_obj()
/// and every polygon triangulated by polygon_triangulation.h (as PLY, OFF and STL polygons are).
TriangleMesh mesh_from_parse(const ParsedObj& parsed, ObjLines lines, const std::string& path) {
    reject_dropped_faces(path, parsed.warnings);

    TriangleMesh mesh;
    mesh.name = stem_of(path);
    mesh.source = path;
    if (parsed.attrib.vertices.size() != 3 * lines.vertices.size())
        throw std::runtime_error(path + ": tinyobjloader found " + std::to_string(parsed.attrib.vertices.size() / 3) +
                                 " vertices but the file has " + std::to_string(lines.vertices.size()) + " `v` lines");
    mesh.vertices = std::move(lines.vertices);

    const auto inconsistent = [&](const std::string& what) {
        throw std::runtime_error(path + ": the `f` lines and tinyobjloader's faces disagree (" + what +
                                 "); expected `f` lines of vertex indices only");
    };
    size_t face = 0;  // the `f` line, 0-based, across every shape
    std::vector<int> polygon;
    for (const tinyobj::shape_t& shape : parsed.shapes) {
        const auto& counts = shape.mesh.num_face_vertices;
        size_t offset = 0;
        for (size_t f = 0; f < counts.size(); ++f, ++face) {
            if (face >= lines.corner_counts.size()) inconsistent("more faces than `f` lines");
            const int64_t n = lines.corner_counts[face];
            if (n < 3)  // tinyobjloader warns of these ("Degenerated face"), refused above
                throw std::runtime_error(path + ": face " + std::to_string(face) + " has " + std::to_string(n) +
                                         " vertices; expected 3 or more");
            if (counts[f] != static_cast<unsigned char>(n) || uint64_t(n) > shape.mesh.indices.size() - offset)
                inconsistent("face " + std::to_string(face) + " has " + std::to_string(n) + " corners");
            polygon.resize(size_t(n));
            for (size_t k = 0; k < size_t(n); ++k) {
                const int v = shape.mesh.indices[offset + k].vertex_index;
                if (v < 0 || size_t(v) >= mesh.vertices.size())
                    throw std::runtime_error(path + ": face " + std::to_string(face) + " refers to vertex " +
                                             std::to_string(int64_t(v) + 1) + ", but the file has " +
                                             std::to_string(mesh.vertices.size()) + " vertices");
                polygon[k] = v;
            }
            triangulate_polygon(mesh.vertices, polygon, mesh.triangles, mesh.polygon_stats);
            offset += size_t(n);
        }
        if (offset != shape.mesh.indices.size()) inconsistent("the corners do not add up");
    }
    if (face != lines.corner_counts.size()) inconsistent("more `f` lines than faces");
    if (mesh.triangles.empty())
        throw std::runtime_error(path + ": no triangles found (expected `f` lines with 3 or more vertices)");
    return mesh;
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
    const std::string_view text = without_utf8_bom(bytes);
    ObjLines lines = read_obj_lines(text, path);
    ParsedObj parsed;
    MemoryStreamBuffer buffer(text);
    std::istream in(&buffer);
    std::string error;
    // Polygons untriangulated: tinyobjloader would cut them its own way (and keep a
    // zero-area triangle of three collinear corners).
    std::vector<tinyobj::material_t> materials;
    std::istringstream no_materials;  // mtllib files are not read (as ParseFromString with no material text)
    tinyobj::MaterialStreamReader material_reader(no_materials);
    if (!tinyobj::LoadObj(&parsed.attrib, &parsed.shapes, &materials, &parsed.warnings, &error, &in, &material_reader,
                          /*triangulate=*/false, /*default_vcols_fallback=*/false))
        throw std::runtime_error(path + ": cannot parse OBJ: " + error);
    return mesh_from_parse(parsed, std::move(lines), path);
}

}  // namespace sdf
