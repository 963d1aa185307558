// OFF reader (Geomview's Object File Format, ASCII): line oriented, since vertex and face
// lines may carry colours and other extra columns after the values read here.
#include <cmath>
#include <climits>
#include <vector>

#include "core/mesh/mesh_file_bytes.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/polygon_triangulation.h"
#include "core/mesh/text_cursor.h"

namespace sdf {
namespace {

/// "OFF" with Geomview's optional prefixes: ST (texture), C (colour), N (normal), 4 (4-D), n (N-D).
bool parse_keyword(std::string_view w, bool& four_d, bool& n_d) {
    if (w.size() < 3 || w.substr(w.size() - 3) != "OFF") return false;
    std::string_view prefix = w.substr(0, w.size() - 3);
    if (prefix.substr(0, 2) == "ST") prefix.remove_prefix(2);
    for (const char c : prefix) {
        if (c == '4') four_d = true;
        else if (c == 'n') n_d = true;
        else if (c != 'C' && c != 'N') return false;
    }
    return true;
}

class OffReader {
public:
    OffReader(const std::string& bytes, const std::string& path) : text_(bytes), path_(path) {}

    TriangleMesh read() {
        std::string_view w;
        if (!next_line(w) || !parse_header_keyword(w)) fail("expected 'OFF' (or COFF, NOFF, STOFF, ...), found " + quoted(w));
        // The counts may follow the keyword on its line (e.g. "OFF 8 6 12").
        if (!line_.next(w) && !next_line(w)) fail("file ends before the vertex and face counts");
        if (w == "BINARY") fail("binary OFF is not supported; write it as ASCII OFF or use PLY");
        const int64_t vertices = count(w, "vertex count");
        if (!line_.next(w)) fail("expected 'vertices faces [edges]' counts");
        const int64_t faces = count(w, "face count");
        // Every vertex and face line takes at least two bytes (a value and its line end).
        if (uint64_t(vertices) * 2 + uint64_t(faces) * 2 > text_.bytes_left() + 1)
            fail("declares " + std::to_string(vertices) + " vertices and " + std::to_string(faces) +
                 " faces, more than the file's remaining " + std::to_string(text_.bytes_left()) + " bytes hold");
        TriangleMesh mesh;
        mesh.vertices.reserve(size_t(vertices));
        for (int64_t i = 0; i < vertices; ++i) {
            if (!next_line(w)) fail("file ends after " + std::to_string(i) + " of " + std::to_string(vertices) + " vertices");
            mesh.vertices.push_back({number(w), next_number(), next_number()});
        }
        std::vector<int> polygon;
        for (int64_t f = 0; f < faces; ++f) {
            if (!next_line(w)) fail("file ends after " + std::to_string(f) + " of " + std::to_string(faces) + " faces");
            int64_t n = 0;
            if (!parse_int(w, n) || n < 3) fail("face " + std::to_string(f) + " has vertex count " + quoted(w) + "; expected 3 or more");
            if (uint64_t(n) > text_.bytes_left() + 64) fail("face " + std::to_string(f) + " declares " + std::to_string(n) + " vertices, more than the file holds");
            polygon.resize(size_t(n));
            for (int& v : polygon) v = index(f, vertices);
            triangulate_polygon(mesh.vertices, polygon, mesh.triangles, mesh.polygon_stats);
        }
        // Geomview writes no edge lines (the edge count is informational), so nothing may follow.
        if (next_line(w))
            fail("data continues after the " + std::to_string(faces) + " faces the header declares (found " + quoted(w) +
                 "; is the face count too small?)");
        check_loaded_mesh(mesh, path_, "OFF file");
        return mesh;
    }

private:
    [[noreturn]] void fail(const std::string& what) const {
        throw_mesh_error(path_, "OFF line " + std::to_string(line_number_), what);
    }

    /// First token of the next line that has one; the rest of that line stays in `line_`.
    bool next_line(std::string_view& first) {
        while (!text_.at_end()) {
            line_number_ = text_.current_line();
            const std::string_view line = text_.rest_of_line();
            line_ = TextCursor(line, 0, line_number_);
            line_.hash_comments = true;
            if (line_.next(first)) return true;
        }
        return false;
    }

    bool parse_header_keyword(std::string_view w) {
        bool four_d = false, n_d = false;
        if (!parse_keyword(w, four_d, n_d)) return false;
        if (four_d || n_d) fail("4-D and n-D OFF (" + quoted(w) + ") are not supported; expected 3-D OFF");
        return true;
    }

    int64_t count(std::string_view w, const char* what) {
        int64_t n = -1;
        if (!parse_int(w, n) || n < 0 || n > INT_MAX) fail(std::string("expected a ") + what + " in [0, 2^31), found " + quoted(w));
        return n;
    }

    double number(std::string_view w) {
        double v = 0;
        if (!parse_double(w, v)) fail("expected a vertex coordinate, found " + quoted(w));
        if (!std::isfinite(v)) fail("non-finite vertex coordinate " + quoted(w));
        return v;
    }

    double next_number() {
        std::string_view w;
        if (!line_.next(w)) fail("vertex line has fewer than 3 coordinates");
        return number(w);
    }

    int index(int64_t face, int64_t vertices) {
        std::string_view w;
        int64_t i = -1;
        if (!line_.next(w)) fail("face " + std::to_string(face) + " has fewer vertex indices than its count");
        if (!parse_int(w, i)) fail("face " + std::to_string(face) + ": expected a vertex index, found " + quoted(w));
        if (i < 0 || i >= vertices)
            fail("face " + std::to_string(face) + " refers to vertex " + std::to_string(i) + "; the file has " +
                 std::to_string(vertices) + " vertices (0-based)");
        return int(i);
    }

    TextCursor text_;
    TextCursor line_{std::string_view()};
    const std::string& path_;
    int line_number_ = 1;
};

}  // namespace

TriangleMesh read_off(const std::string& bytes, const std::string& path) { return OffReader(bytes, path).read(); }

}  // namespace sdf
