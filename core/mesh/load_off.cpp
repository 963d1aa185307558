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
            note_face_shaped_vertex_line(vertices);
            mesh.vertices.push_back({number(w), next_number(), next_number()});
        }
        std::vector<int> polygon;
        for (int64_t f = 0; f < faces; ++f) {
            if (!next_line(w)) {
                refuse_vertex_count_too_large(vertices, faces, f);
                fail("file ends after " + std::to_string(f) + " of " + std::to_string(faces) + " faces (expected " +
                     std::to_string(faces) + " face lines, found " + std::to_string(f) +
                     "; is the face count too large, or the file truncated?)");
            }
            int64_t n = 0;
            if (!parse_int(w, n) || n < 3)
                face_fail(vertices, faces, f, "face " + std::to_string(f) + " has vertex count " + quoted(w) + "; expected 3 or more");
            // A face's indices are on its line, each a digit and a separator at least (checked
            // before the corners are allocated).
            if (uint64_t(n) > (line_.bytes_left() + 1) / 2)
                face_fail(vertices, faces, f, "face " + std::to_string(f) + " declares " + std::to_string(n) +
                                                  " vertices, more than its line holds (" +
                                                  std::to_string(line_.bytes_left()) + " bytes after the count)");
            polygon.resize(size_t(n));
            for (int& v : polygon) v = index(f, vertices, faces);
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
            line_text_ = line.substr(0, line.find('#'));
            while (!line_text_.empty() && (line_text_.back() == ' ' || line_text_.back() == '\t' || line_text_.back() == '\r'))
                line_text_.remove_suffix(1);
            if (line_.next(first)) return true;
        }
        return false;
    }

    /// Whether the current line reads as a face line "n i_0 ... i_(n-1) [colour]": n >= 3
    /// integers in [0, vertices) after it, and at most four colour values.
    bool face_shaped(int64_t vertices) const {
        TextCursor words(line_text_);
        std::string_view w;
        int64_t n = 0, i = 0;
        if (!words.next(w) || !parse_int(w, n) || n < 3) return false;
        for (int64_t k = 0; k < n; ++k)
            if (!words.next(w) || !parse_int(w, i) || i < 0 || i >= vertices) return false;
        int extra = 0;
        while (words.next(w)) ++extra;
        return extra <= 4;
    }

    /// Whether the current line reads as a vertex line: three or more numbers, not a face.
    bool vertex_shaped(int64_t vertices) const {
        TextCursor words(line_text_);
        std::string_view w;
        double v = 0;
        int numbers = 0;
        int64_t first = -1;
        while (words.next(w)) {
            if (!parse_double(w, v)) return false;
            if (numbers++ == 0 && !parse_int(w, first)) first = -1;
        }
        if (first >= 0 && numbers == first + 1) return false;  // a face's shape, however bad ("2 0 1")
        // "x y z", or more columns (colours, normals) when the first is no face's vertex count.
        return (numbers == 3 || (numbers > 3 && first < 3)) && !face_shaped(vertices);
    }

    /// Keeps the run of face-shaped lines that ends the vertex section: a vertex count one
    /// (or k) too large reads the first face line(s) as vertices.
    void note_face_shaped_vertex_line(int64_t vertices) {
        if (!face_shaped(vertices)) { face_run_ = 0; return; }
        if (face_run_++ > 0) return;
        face_run_line_ = line_number_;
        face_run_text_ = line_text_;
    }

    /// The faces ran out `faces - read` lines early: when as many face-shaped lines end the
    /// vertex section, the vertex count is too large by that many.
    void refuse_vertex_count_too_large(int64_t vertices, int64_t faces, int64_t read) {
        const int64_t missing = faces - read;
        if (face_run_ < missing) return;
        line_number_ = face_run_line_;
        fail("expected " + std::to_string(vertices) + " vertex lines, found " + std::to_string(vertices - missing) +
             " before the faces: this line (" + quoted(face_run_text_) + ") is a face line, read as vertex " +
             std::to_string(vertices - face_run_) + ", and the file then ends after " + std::to_string(read) + " of " +
             std::to_string(faces) + " faces (is the vertex count too large by " + std::to_string(missing) + "?)");
    }

    /// A face line that does not read: named as a vertex line where it is one (the vertex
    /// count is too small), else with `what`.
    [[noreturn]] void face_fail(int64_t vertices, int64_t faces, int64_t f, const std::string& what) const {
        if (!vertex_shaped(vertices)) fail(what);
        fail("expected face " + std::to_string(f) + " of " + std::to_string(faces) + ", found a vertex line (" +
             quoted(line_text_) + "): the header declares " + std::to_string(vertices) +
             " vertices, but vertex lines continue after them (is the vertex count too small?)");
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

    int index(int64_t face, int64_t vertices, int64_t faces) {
        std::string_view w;
        int64_t i = -1;
        if (!line_.next(w)) face_fail(vertices, faces, face, "face " + std::to_string(face) + " has fewer vertex indices than its count");
        if (!parse_int(w, i)) face_fail(vertices, faces, face, "face " + std::to_string(face) + ": expected a vertex index, found " + quoted(w));
        if (i < 0 || i >= vertices)
            face_fail(vertices, faces, face, "face " + std::to_string(face) + " refers to vertex " + std::to_string(i) + "; the file has " +
                 std::to_string(vertices) + " vertices (0-based)");
        return int(i);
    }

    TextCursor text_;
    TextCursor line_{std::string_view()};
    std::string_view line_text_;  ///< the current line without its comment, for messages
    const std::string& path_;
    int line_number_ = 1;
    int64_t face_run_ = 0;        ///< face-shaped lines ending the vertex section so far
    int face_run_line_ = 0;       ///< the first of them
    std::string_view face_run_text_;
};

}  // namespace

TriangleMesh read_off(const std::string& bytes, const std::string& path) { return OffReader(bytes, path).read(); }

}  // namespace sdf
