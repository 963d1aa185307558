// STL reader, binary and ASCII. Binary is recognised by its size (84 + 50 n bytes for the n
// triangles its header declares): many binary files begin their 80-byte header with
// "solid", so that word alone does not make a file ASCII.
#include <cmath>
#include <cstring>
#include <vector>

#include "core/mesh/mesh_file_bytes.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/text_cursor.h"

namespace sdf {
namespace {

constexpr size_t kBinaryHeader = 84, kBinaryTriangle = 50;

bool starts_with_solid(const std::string& bytes) {
    size_t i = 0;
    while (i < bytes.size() && (bytes[i] == ' ' || bytes[i] == '\t' || bytes[i] == '\r' || bytes[i] == '\n')) ++i;
    return bytes.compare(i, 5, "solid") == 0;
}

uint32_t binary_count(const std::string& bytes) {
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);  // little-endian, as the host
    return n;
}

TriangleMesh read_binary(const std::string& bytes, const std::string& path) {
    const uint32_t n = binary_count(bytes);
    TriangleMesh mesh;
    mesh.triangles.reserve(n);
    ExactVertexWelder welder(mesh.vertices);
    for (uint32_t f = 0; f < n; ++f) {
        const char* record = bytes.data() + kBinaryHeader + kBinaryTriangle * size_t(f);
        Int3 t;
        for (int k = 0; k < 3; ++k) {
            float xyz[3];
            std::memcpy(xyz, record + 12 * (k + 1), 12);  // after the facet normal
            const Vec3d p{double(xyz[0]), double(xyz[1]), double(xyz[2])};
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                throw_mesh_error(path, "binary STL triangle " + std::to_string(f) + " (byte " +
                                           std::to_string(kBinaryHeader + kBinaryTriangle * size_t(f)) + ")",
                                 "non-finite vertex coordinate");
            t[k] = welder.id_of(p);
        }
        mesh.triangles.push_back(t);
    }
    return mesh;
}

class AsciiStl {
public:
    AsciiStl(const std::string& bytes, const std::string& path) : words_(bytes), path_(path) {}

    TriangleMesh read() {
        ExactVertexWelder welder(mesh_.vertices);
        std::vector<int> polygon;
        expect("solid");
        words_.rest_of_line();  // the solid's name
        for (std::string_view w; words_.next(w);) {
            if (w == "endsolid") {
                words_.rest_of_line();
                if (words_.at_end()) break;
                expect("solid");
                words_.rest_of_line();
                continue;
            }
            if (w != "facet") fail("expected 'facet' or 'endsolid', found " + quoted(w));
            expect("normal");
            for (int k = 0; k < 3; ++k) number();  // normals are recomputed from the vertices
            expect("outer");
            expect("loop");
            polygon.clear();
            std::string_view v;
            while (next(v) == "vertex") polygon.push_back(welder.id_of({number(), number(), number()}));
            if (v != "endloop") fail("expected 'vertex' or 'endloop', found " + quoted(v));
            if (polygon.size() < 3) fail("facet has " + std::to_string(polygon.size()) + " vertices; expected 3 or more");
            expect("endfacet");
            for (size_t j = 1; j + 1 < polygon.size(); ++j) mesh_.triangles.push_back({polygon[0], polygon[j], polygon[j + 1]});
        }
        return std::move(mesh_);
    }

private:
    [[noreturn]] void fail(const std::string& what) const {
        throw_mesh_error(path_, "ASCII STL line " + std::to_string(words_.line()), what);
    }

    std::string_view next(std::string_view& w) {
        if (!words_.next(w)) fail("file ends early (truncated? no 'endsolid')");
        return w;
    }

    void expect(std::string_view keyword) {
        std::string_view w;
        if (next(w) != keyword) fail("expected '" + std::string(keyword) + "', found " + quoted(w));
    }

    double number() {
        std::string_view w;
        double v = 0;
        if (!parse_double(next(w), v)) fail("expected a number, found " + quoted(w));
        if (!std::isfinite(v)) fail("non-finite coordinate " + quoted(w));
        return v;
    }

    TextCursor words_;
    const std::string& path_;
    TriangleMesh mesh_;
};

}  // namespace

TriangleMesh read_stl(const std::string& bytes, const std::string& path) {
    const bool sized_binary = bytes.size() >= kBinaryHeader &&
                              bytes.size() == kBinaryHeader + kBinaryTriangle * uint64_t(binary_count(bytes));
    TriangleMesh mesh;
    if (sized_binary) {
        mesh = read_binary(bytes, path);
    } else if (starts_with_solid(bytes)) {
        mesh = AsciiStl(bytes, path).read();
    } else if (bytes.size() < kBinaryHeader) {
        throw_mesh_error(path, "STL", "file has " + std::to_string(bytes.size()) +
                                          " bytes: too short for binary STL (84-byte header) and not ASCII STL (no 'solid')");
    } else {
        const uint64_t n = binary_count(bytes);
        throw_mesh_error(path, "binary STL header",
                         "declares " + std::to_string(n) + " triangles, which take " +
                             std::to_string(kBinaryHeader + kBinaryTriangle * n) + " bytes, but the file has " +
                             std::to_string(bytes.size()) + " (truncated, or not STL)");
    }
    check_loaded_mesh(mesh, path, "STL file");
    return mesh;
}

}  // namespace sdf
