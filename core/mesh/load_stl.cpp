// STL reader, binary and ASCII. Binary is recognised by its size (84 + 50 n bytes for the n
// triangles its header declares): many binary files begin their 80-byte header with
// "solid", so that word alone does not make a file ASCII; nor does it when control bytes
// (binary data) follow it.
#include <cmath>
#include <cstring>
#include <vector>

#include "core/mesh/mesh_file_bytes.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/polygon_triangulation.h"
#include "core/mesh/text_cursor.h"

namespace sdf {
namespace {

constexpr size_t kBinaryHeader = 84, kBinaryTriangle = 50;

bool starts_with_solid(std::string_view bytes) {
    TextCursor words(bytes.substr(0, 4096));
    std::string_view w;
    return words.next(w) && equals_keyword(w, "solid");
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

/// ASCII STL: "solid NAME", facets "facet normal nx ny nz / outer loop / vertex x y z ...
/// / endloop / endfacet", "endsolid NAME", possibly several solids. Keywords in any case
/// (many CAD exporters write them in capitals), tokens on any lines (some write the whole
/// file on one). The facet normal must be three numbers but is not used (nor checked for
/// being finite): the sign comes from the vertices' order.
class AsciiStl {
public:
    AsciiStl(const std::string& bytes, const std::string& path) : words_(bytes), path_(path) {}

    TriangleMesh read() {
        ExactVertexWelder welder(mesh_.vertices);
        std::vector<int> polygon;
        expect("solid");
        skip_name();
        for (std::string_view w;;) {
            if (!words_.next(w))
                fail("file ends after " + std::to_string(facets_) + " facets without 'endsolid' (truncated?)");
            if (equals_keyword(w, "endsolid")) {
                skip_name();
                if (words_.at_end()) break;
                expect("solid");
                skip_name();
                continue;
            }
            if (!equals_keyword(w, "facet")) fail("expected 'facet' or 'endsolid', found " + quoted(w));
            expect("normal");
            for (int k = 0; k < 3; ++k) normal_component();
            expect("outer");
            expect("loop");
            polygon.clear();
            std::string_view v;
            while (equals_keyword(next(v), "vertex")) polygon.push_back(welder.id_of({number(), number(), number()}));
            if (!equals_keyword(v, "endloop")) fail("expected 'vertex' or 'endloop', found " + quoted(v));
            if (polygon.size() < 3) fail("facet has " + std::to_string(polygon.size()) + " vertices; expected 3 or more");
            expect("endfacet");
            triangulate_polygon(mesh_.vertices, polygon, mesh_.triangles, mesh_.polygon_stats);
            ++facets_;
        }
        return std::move(mesh_);
    }

private:
    [[noreturn]] void fail(const std::string& what) const {
        throw_mesh_error(path_, "ASCII STL line " + std::to_string(words_.line()), what);
    }

    /// The name after "solid" or "endsolid": the rest of its line, up to a keyword that
    /// begins the next statement (a one-line file has "solid s facet normal ...").
    void skip_name() {
        const int line = words_.line();
        std::string_view w;
        for (int at = 0; words_.peek(w, at) && at == line;) {
            if (equals_keyword(w, "facet") || equals_keyword(w, "endsolid") || equals_keyword(w, "solid")) return;
            words_.next(w);
        }
    }

    std::string_view next(std::string_view& w) {
        if (!words_.next(w))
            fail("file ends inside facet " + std::to_string(facets_) + " (truncated? no 'endfacet' and 'endsolid')");
        return w;
    }

    void expect(std::string_view keyword) {
        std::string_view w;
        if (!equals_keyword(next(w), keyword)) fail("expected '" + std::string(keyword) + "', found " + quoted(w));
    }

    double number() {
        std::string_view w;
        double v = 0;
        if (!parse_double(next(w), v)) fail("expected a vertex coordinate (a number), found " + quoted(w));
        if (!std::isfinite(v)) fail("non-finite vertex coordinate " + quoted(w));
        return v;
    }

    void normal_component() {
        std::string_view w;
        double v = 0;
        if (!parse_double(next(w), v))
            fail("expected a facet normal component (a number, even 'nan': normals are not used), found " + quoted(w));
    }

    TextCursor words_;
    const std::string& path_;
    TriangleMesh mesh_;
    int64_t facets_ = 0;
};

}  // namespace

// Text has no control bytes but white space; a binary STL has them within its first
// records (NUL padding, the triangle count's high bytes, small floats).
bool holds_binary_bytes(std::string_view bytes) {
    for (const char c : bytes.substr(0, kBinaryHeader + 4 * kBinaryTriangle)) {
        const auto b = static_cast<unsigned char>(c);
        if ((b < 0x20 && b != '\t' && b != '\n' && b != '\r' && b != '\f' && b != '\v') || b == 0x7f) return true;
    }
    return false;
}

bool is_ascii_stl_start(std::string_view bytes) { return starts_with_solid(bytes) && !holds_binary_bytes(bytes); }

TriangleMesh read_stl(const std::string& bytes, const std::string& path) {
    const bool sized_binary = bytes.size() >= kBinaryHeader &&
                              bytes.size() == kBinaryHeader + kBinaryTriangle * uint64_t(binary_count(bytes));
    TriangleMesh mesh;
    if (sized_binary) {
        mesh = read_binary(bytes, path);
    } else if (is_ascii_stl_start(bytes)) {
        mesh = AsciiStl(bytes, path).read();
    } else if (bytes.size() < kBinaryHeader) {
        throw_mesh_error(path, "STL", "file has " + std::to_string(bytes.size()) +
                                          " bytes: too short for binary STL (84-byte header) and not ASCII STL (no 'solid')");
    } else {
        const uint64_t n = binary_count(bytes);
        throw_mesh_error(path, "binary STL header",
                         "declares " + std::to_string(n) + " triangles, which take " +
                             std::to_string(kBinaryHeader + kBinaryTriangle * n) + " bytes, but the file has " +
                             std::to_string(bytes.size()) +
                             (bytes.size() < kBinaryHeader + kBinaryTriangle * n
                                  ? " (truncated, or not STL)"
                                  : " (data after the declared triangles: is the count too small? or not STL)") +
                             (starts_with_solid(bytes) ? "; the header begins with 'solid', but the file holds binary "
                                                         "bytes, so it is not ASCII STL"
                                                       : ""));
    }
    check_loaded_mesh(mesh, path, "STL file");
    return mesh;
}

}  // namespace sdf
