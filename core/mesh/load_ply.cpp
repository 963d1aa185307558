// PLY reader: the header grammar of Turk's "The PLY Polygon File Format" (1994), the three
// encodings; polygon faces triangulated by polygon_triangulation.h. Sizes in the header are checked against
// the bytes that follow before anything is allocated.
#include <algorithm>
#include <climits>
#include <cstring>
#include <optional>
#include <vector>

#include "core/mesh/mesh_file_bytes.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/polygon_triangulation.h"
#include "core/mesh/text_cursor.h"

namespace sdf {
namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::Float32;  ///< the item type of a list
    bool is_list = false;
    PlyType count_type = PlyType::UInt8;
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> properties;
};

struct PlyHeader {
    PlyEncoding encoding = PlyEncoding::Ascii;
    std::vector<PlyElement> elements;
    size_t data_offset = 0;  ///< first byte after "end_header\n"
    int data_line = 0;       ///< line of the first data byte (ascii)
};

bool type_from_name(std::string_view name, PlyType& type) {
    static const struct { const char* names[2]; PlyType type; } table[] = {
        {{"char", "int8"}, PlyType::Int8},     {{"uchar", "uint8"}, PlyType::UInt8},
        {{"short", "int16"}, PlyType::Int16},  {{"ushort", "uint16"}, PlyType::UInt16},
        {{"int", "int32"}, PlyType::Int32},    {{"uint", "uint32"}, PlyType::UInt32},
        {{"float", "float32"}, PlyType::Float32}, {{"double", "float64"}, PlyType::Float64}};
    for (const auto& entry : table)
        if (name == entry.names[0] || name == entry.names[1]) { type = entry.type; return true; }
    return false;
}

size_t size_of(PlyType t) {
    switch (t) {
        case PlyType::Int8: case PlyType::UInt8: return 1;
        case PlyType::Int16: case PlyType::UInt16: return 2;
        case PlyType::Int32: case PlyType::UInt32: case PlyType::Float32: return 4;
        case PlyType::Float64: return 8;
    }
    return 0;
}

bool is_integer(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

const char* kTypeNames = "char, uchar, short, ushort, int, uint, float, double (or int8 ... float64)";

class HeaderParser {
public:
    HeaderParser(const std::string& bytes, const std::string& path) : bytes_(bytes), path_(path) {}

    PlyHeader parse() {
        line_ = 0;
        const std::string_view magic = next_line();
        if (magic != "ply") fail("expected 'ply' as the first line, found " + quoted(magic));
        bool have_format = false;
        for (;;) {
            if (pos_ >= bytes_.size()) fail("header ends without 'end_header'");
            TextCursor words(next_line());
            std::string_view keyword;
            if (!words.next(keyword)) continue;
            if (keyword == "end_header") break;
            if (keyword == "comment" || keyword == "obj_info") continue;
            if (keyword == "format") { parse_format(words); have_format = true; }
            else if (keyword == "element") parse_element(words);
            else if (keyword == "property") parse_property(words);
            else fail("unknown header keyword " + quoted(keyword) +
                      "; expected format, element, property, comment, obj_info or end_header");
        }
        if (!have_format) fail("no 'format' line in the header");
        header_.data_offset = pos_;
        header_.data_line = line_ + 1;
        return header_;
    }

private:
    /// The next header line without its "\r\n" or "\n".
    std::string_view next_line() {
        const size_t end = std::min(bytes_.find('\n', pos_), bytes_.size());
        std::string_view line(bytes_.data() + pos_, end - pos_);
        pos_ = std::min(end + 1, bytes_.size());
        ++line_;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        return line;
    }

    [[noreturn]] void fail(const std::string& what) const {
        throw_mesh_error(path_, "PLY header line " + std::to_string(line_), what);
    }

    void parse_format(TextCursor& words) {
        std::string_view encoding, version;
        words.next(encoding);
        if (encoding == "ascii") header_.encoding = PlyEncoding::Ascii;
        else if (encoding == "binary_little_endian") header_.encoding = PlyEncoding::BinaryLittleEndian;
        else if (encoding == "binary_big_endian") header_.encoding = PlyEncoding::BinaryBigEndian;
        else fail("unknown format " + quoted(encoding) + "; expected ascii, binary_little_endian or binary_big_endian");
        if (!words.next(version) || version != "1.0") fail("expected version 1.0, found " + quoted(version));
    }

    void parse_element(TextCursor& words) {
        std::string_view name, count;
        int64_t n = -1;
        if (!words.next(name) || !words.next(count) || !parse_int(count, n) || n < 0)
            fail("expected 'element <name> <count>' with a count >= 0");
        header_.elements.push_back({std::string(name), uint64_t(n), {}});
    }

    void parse_property(TextCursor& words) {
        if (header_.elements.empty()) fail("'property' before any 'element'");
        PlyProperty p;
        std::string_view type, name;
        words.next(type);
        if (type == "list") {
            std::string_view count_type, item_type;
            words.next(count_type);
            words.next(item_type);
            p.is_list = true;
            if (!type_from_name(count_type, p.count_type) || !type_from_name(item_type, p.type))
                fail("unknown list type " + quoted(count_type) + " or " + quoted(item_type) + "; expected " + kTypeNames);
            if (!is_integer(p.count_type)) fail("list count type " + quoted(count_type) + " must be an integer type");
        } else if (!type_from_name(type, p.type)) {
            fail("unknown property type " + quoted(type) + "; expected " + kTypeNames + " or list");
        }
        if (!words.next(name)) fail("property without a name");
        p.name = std::string(name);
        header_.elements.back().properties.push_back(p);
    }

    const std::string& bytes_;
    const std::string& path_;
    PlyHeader header_;
    size_t pos_ = 0;
    int line_ = 0;
};

/// Values of the data section, ascii tokens or binary numbers, read one at a time.
class PlyValues {
public:
    PlyValues(const std::string& bytes, const PlyHeader& h, const std::string& path)
        : bytes_(bytes), encoding_(h.encoding), pos_(h.data_offset), text_(bytes, h.data_offset, h.data_line), path_(path) {}

    /// The next value as a double (integers up to 2^53 exactly).
    double value(PlyType type) {
        return encoding_ == PlyEncoding::Ascii ? ascii_value(type) : binary_value(type);
    }

    size_t bytes_left() const { return encoding_ == PlyEncoding::Ascii ? text_.bytes_left() : bytes_.size() - pos_; }

    /// Where the reader is, for messages: "line 12" or "byte 345".
    std::string place() const {
        return encoding_ == PlyEncoding::Ascii ? "line " + std::to_string(text_.line()) : "byte " + std::to_string(pos_);
    }

    std::string element_place(const std::string& element, uint64_t index) const {
        return "PLY element '" + element + "' " + std::to_string(index) + " (" + place() + ")";
    }

    bool trailing_data() { return encoding_ == PlyEncoding::Ascii ? !text_.at_end() : pos_ != bytes_.size(); }

    /// Where what follows begins: "line 13 ('3')" (its first word) or "byte 345".
    std::string next_place() const {
        std::string_view w;
        int line = 0;
        if (encoding_ == PlyEncoding::Ascii && text_.peek(w, line)) return "line " + std::to_string(line) + " (" + quoted(w) + ")";
        return "byte " + std::to_string(pos_);
    }

    /// Ascii PLY writes one element per line; reading each on its own line turns a wrong
    /// count in the header into a message at the line where it shows (a vertex line with
    /// a face's values), not at a later, unrelated element.
    void begin_element(uint64_t index, uint64_t count) {
        index_ = index;
        count_ = count;
        element_line_ = -1;
        values_ = 0;
        std::string_view w;
        int line = 0;
        element_start_ = encoding_ == PlyEncoding::Ascii && text_.peek(w, line) ? size_t(w.data() - bytes_.data()) : bytes_.size();
    }

    /// The ascii line the current element begins on (for messages).
    std::string_view element_text() const {
        std::string_view rest = std::string_view(bytes_).substr(element_start_);
        rest = rest.substr(0, rest.find('\n'));
        if (!rest.empty() && rest.back() == '\r') rest.remove_suffix(1);
        return rest;
    }

    bool ascii() const { return encoding_ == PlyEncoding::Ascii; }
    void end_element(const PlyElement& e) {
        std::string_view w;
        int line = 0;
        if (encoding_ == PlyEncoding::Ascii && text_.peek(w, line) && line == element_line_)
            throw_mesh_error(path_, "PLY element '" + element_ + "' " + std::to_string(index_) + " (line " + std::to_string(line) + ")",
                             "the line has more values than the element's properties (" + property_names(e) + ") take: " +
                                 quoted(w) + " follows the " + std::to_string(values_) +
                                 " read (is the header's count of '" + element_ + "' elements too large?)");
    }

    static std::string property_names(const PlyElement& e) {
        std::string names;
        for (const PlyProperty& p : e.properties) names += (names.empty() ? "" : " ") + p.name + (p.is_list ? "[]" : "");
        return names;
    }

    std::string element_, where_;  ///< set by the reader for errors raised here
    uint64_t index_ = 0, count_ = 0;

private:
    [[noreturn]] void fail(const std::string& what) const { throw_mesh_error(path_, element_place(element_, index_), what); }

    double ascii_value(PlyType type) {
        std::string_view token;
        if (!text_.next(token)) {
            if (values_ == 0)
                fail("file ends after " + std::to_string(index_) + " of " + std::to_string(count_) + " '" + element_ +
                     "' elements (expected " + std::to_string(count_) + " lines of them, found " + std::to_string(index_) +
                     "; is the header's count too large, or the file truncated?)");
            fail("file ends early (truncated?); expected a value");
        }
        if (element_line_ < 0) element_line_ = text_.line();
        if (text_.line() != element_line_)
            throw_mesh_error(path_, "PLY element '" + element_ + "' " + std::to_string(index_) + " (line " +
                                        std::to_string(element_line_) + ")",
                             "the line ends after " + std::to_string(values_) +
                                 " values; expected the rest of the element on it (one element per line)");
        ++values_;
        double v = 0;
        if (is_integer(type)) {
            int64_t i = 0;
            if (!parse_int(token, i)) fail("expected an integer, found " + quoted(token));
            v = double(i);
        } else if (!parse_double(token, v)) {
            fail("expected a number, found " + quoted(token));
        }
        return v;
    }

    template <typename T>
    T load() {
        T v;
        unsigned char raw[sizeof(T)];
        std::memcpy(raw, bytes_.data() + pos_, sizeof(T));
        pos_ += sizeof(T);
        if (encoding_ == PlyEncoding::BinaryBigEndian) std::reverse(raw, raw + sizeof(T));  // host is little-endian
        std::memcpy(&v, raw, sizeof(T));
        return v;
    }

    double binary_value(PlyType type) {
        if (bytes_.size() - pos_ < size_of(type)) fail("file ends early (truncated?)");
        switch (type) {
            case PlyType::Int8: return load<int8_t>();
            case PlyType::UInt8: return load<uint8_t>();
            case PlyType::Int16: return load<int16_t>();
            case PlyType::UInt16: return load<uint16_t>();
            case PlyType::Int32: return load<int32_t>();
            case PlyType::UInt32: return load<uint32_t>();
            case PlyType::Float32: return load<float>();
            case PlyType::Float64: return load<double>();
        }
        return 0;
    }

    const std::string& bytes_;
    PlyEncoding encoding_;
    size_t pos_;
    TextCursor text_;
    const std::string& path_;
    int element_line_ = -1;  ///< line of the element being read (ascii)
    size_t element_start_ = 0;  ///< its first byte (ascii)
    uint64_t values_ = 0;    ///< values of it read so far
};

/// Fewest bytes one element can take: binary sizes, or one character and a separator per ascii value.
uint64_t min_element_bytes(const PlyElement& e, PlyEncoding encoding) {
    uint64_t n = 0;
    for (const PlyProperty& p : e.properties)
        n += encoding == PlyEncoding::Ascii ? 2 : size_of(p.is_list ? p.count_type : p.type);
    return n;
}

void check_sizes(const PlyHeader& h, const std::string& bytes, const std::string& path) {
    uint64_t needed = 0;
    for (const PlyElement& e : h.elements) {
        const uint64_t per = min_element_bytes(e, h.encoding);
        if (per > 0 && e.count > (uint64_t(1) << 62) / per)
            throw_mesh_error(path, "PLY header", "element '" + e.name + "' count " + std::to_string(e.count) + " is impossibly large");
        needed += per * e.count;
    }
    const uint64_t available = bytes.size() - h.data_offset + (h.encoding == PlyEncoding::Ascii ? 1 : 0);
    if (needed > available)
        throw_mesh_error(path, "PLY header",
                         "the declared elements need at least " + std::to_string(needed) + " bytes of data, but only " +
                             std::to_string(available) + " follow the header (truncated, or wrong counts)");
}

struct VertexLayout {
    int x = -1, y = -1, z = -1;
};

struct Reader {
    const PlyHeader& header;
    PlyValues& values;
    const std::string& path;
    TriangleMesh& mesh;
    uint64_t vertex_count = 0;
    const PlyElement* vertex_element = nullptr;
    std::vector<double> scratch;
    PolygonList polygons;  ///< triangulated once every vertex is read (elements may come in any order)

    void read_vertices(const PlyElement& e) {
        VertexLayout at;
        for (size_t k = 0; k < e.properties.size(); ++k) {
            const PlyProperty& p = e.properties[k];
            int* slot = p.name == "x" ? &at.x : p.name == "y" ? &at.y : p.name == "z" ? &at.z : nullptr;
            if (slot && p.is_list) throw_mesh_error(path, "PLY header", "vertex property '" + p.name + "' is a list; expected a scalar");
            if (slot) *slot = int(k);
        }
        if (at.x < 0 || at.y < 0 || at.z < 0)
            throw_mesh_error(path, "PLY header", "element 'vertex' lacks property x, y or z");
        mesh.vertices.reserve(size_t(e.count));
        scratch.resize(e.properties.size());
        for (uint64_t i = 0; i < e.count; ++i) {
            values.begin_element(i, e.count);
            read_element(e);
            values.end_element(e);
            mesh.vertices.push_back({scratch[size_t(at.x)], scratch[size_t(at.y)], scratch[size_t(at.z)]});
        }
    }

    /// Reads every property of one element into `scratch` (lists are skipped).
    void read_element(const PlyElement& e) {
        for (size_t k = 0; k < e.properties.size(); ++k) {
            const PlyProperty& p = e.properties[k];
            if (!p.is_list) { scratch[k] = values.value(p.type); continue; }
            skip_list(e, p);
        }
    }

    void skip_list(const PlyElement& e, const PlyProperty& p) {
        const double n = values.value(p.count_type);
        if (n < 0) fail(e, "list '" + p.name + "' has a negative item count (" + std::to_string(int64_t(n)) + ")");
        if (n > double(values.bytes_left()))
            fail(e, "list '" + p.name + "' declares " + std::to_string(int64_t(n)) + " items, more than the file's remaining " +
                        std::to_string(values.bytes_left()) + " bytes hold (truncated, or a wrong count?)");
        for (int64_t j = 0; j < int64_t(n); ++j) values.value(p.type);
    }

    void read_faces(const PlyElement& e) {
        int list = -1;
        for (size_t k = 0; k < e.properties.size(); ++k)
            if (e.properties[k].is_list && (e.properties[k].name == "vertex_indices" || e.properties[k].name == "vertex_index"))
                list = int(k);
        if (list < 0) throw_mesh_error(path, "PLY header", "element 'face' lacks a list property 'vertex_indices' (or 'vertex_index')");
        if (!is_integer(e.properties[size_t(list)].type))
            throw_mesh_error(path, "PLY header", "face indices must have an integer type");
        std::vector<int> polygon;
        for (uint64_t i = 0; i < e.count; ++i) {
            values.begin_element(i, e.count);
            try {
                for (size_t k = 0; k < e.properties.size(); ++k) {
                    const PlyProperty& p = e.properties[k];
                    if (int(k) == list) read_polygon(e, p, polygon);
                    else if (!p.is_list) values.value(p.type);
                    else skip_list(e, p);
                }
                values.end_element(e);
            } catch (const std::runtime_error&) {
                refuse_vertex_line_among_faces(e);
                throw;
            }
            polygons.add(polygon);
        }
    }

    /// A face that does not read, on an ascii line that reads as a vertex (as many numbers
    /// as the vertex element has properties): the header's vertex count is too small.
    void refuse_vertex_line_among_faces(const PlyElement& e) const {
        if (!values.ascii() || !vertex_element) return;
        for (const PlyProperty& p : vertex_element->properties) if (p.is_list) return;
        const std::string_view line = values.element_text();
        TextCursor words(line);
        std::string_view w;
        double v = 0;
        int64_t first = -1;
        size_t numbers = 0;
        while (words.next(w)) {
            if (!parse_double(w, v)) return;
            if (numbers++ == 0 && !parse_int(w, first)) first = -1;
        }
        if (first >= 0 && numbers == size_t(first) + 1) return;  // a face's shape, however bad ("2 0 1")
        if (numbers != vertex_element->properties.size()) return;
        fail(e, "expected face " + std::to_string(values.index_) + " of " + std::to_string(e.count) +
                    ", found a vertex line (" + quoted(line) + "): the header declares " + std::to_string(vertex_count) +
                    " vertices, but vertex lines continue after them (is the header's count of 'vertex' elements too "
                    "small?)");
    }

    void read_polygon(const PlyElement& e, const PlyProperty& p, std::vector<int>& polygon) {
        const double n = values.value(p.count_type);
        if (n < 3) fail(e, "face has " + std::to_string(int64_t(n)) + " vertices; expected 3 or more");
        const double min_item_bytes = header.encoding == PlyEncoding::Ascii ? 2.0 : double(size_of(p.type));
        if (n * min_item_bytes > double(values.bytes_left()) + 1)
            fail(e, "face declares " + std::to_string(int64_t(n)) + " vertices, more than the file holds");
        polygon.resize(size_t(n));
        for (int& v : polygon) {
            const double index = values.value(p.type);
            if (index < 0 || index >= double(vertex_count))
                fail(e, "vertex index " + std::to_string(int64_t(index)) + " out of range; the file has " +
                            std::to_string(vertex_count) + " vertices");
            v = int(index);
        }
    }

    void skip(const PlyElement& e) {
        scratch.resize(e.properties.size());
        for (uint64_t i = 0; i < e.count; ++i) {
            values.begin_element(i, e.count);
            read_element(e);
            values.end_element(e);
        }
    }

    [[noreturn]] void fail(const PlyElement& e, const std::string& what) const {
        throw_mesh_error(path, values.element_place(e.name, values.index_), what);
    }
};

/// Largest item count a list's count type can hold.
uint64_t max_list_count(PlyType t) {
    switch (t) {
        case PlyType::Int8: return 127;
        case PlyType::UInt8: return 255;
        case PlyType::Int16: return 32767;
        case PlyType::UInt16: return 65535;
        case PlyType::Int32: return 2147483647;
        default: return 4294967295;
    }
}

/// Most bytes one binary element can take, and its description for messages.
uint64_t max_element_bytes(const PlyElement& e, bool& fixed) {
    uint64_t n = 0;
    fixed = true;
    for (const PlyProperty& p : e.properties) {
        n += size_of(p.is_list ? p.count_type : p.type);
        if (p.is_list) { n += max_list_count(p.count_type) * size_of(p.type); fixed = false; }
    }
    return n;
}

/// The first byte after the header's "end_header" line (its line end included: LF, CRLF or
/// a lone CR), or npos when `bytes` do not hold it. Only a line whose only word is
/// end_header ends the header (not a comment that mentions it).
size_t ply_header_end(std::string_view bytes) {
    for (size_t at = 0; at < bytes.size();) {
        const size_t eol = bytes.find_first_of("\r\n", at);
        if (eol == std::string_view::npos) return eol;  // the line may not be complete yet
        TextCursor words(bytes.substr(at, eol - at));
        std::string_view w;
        const bool end = words.next(w) && w == "end_header" && !words.next(w);
        at = eol + 1 + (bytes[eol] == '\r' && eol + 1 < bytes.size() && bytes[eol + 1] == '\n');
        if (end) return bytes[eol] == '\r' && eol + 1 == bytes.size() ? std::string_view::npos : at;  // CR: LF may follow
    }
    return std::string_view::npos;
}

}  // namespace

std::optional<ContentLimit> ply_size_limit(std::string_view bytes, const std::string& path) {
    // A header no longer than this is looked for: the check runs after every decompressed
    // megabyte, and a file without "end_header" is the reader's to refuse.
    constexpr size_t kLongestHeader = size_t(16) << 20;
    const size_t end = ply_header_end(bytes.substr(0, kLongestHeader));
    if (end == std::string_view::npos) return bytes.size() < kLongestHeader ? std::nullopt : std::optional(ContentLimit{});
    // The header as read_ply() sees it: lone CRs (classic Mac line ends) become LFs.
    std::string text(bytes.substr(0, end));
    for (size_t i = 0; i < text.size(); ++i)
        if (text[i] == '\r' && (i + 1 == text.size() || text[i + 1] != '\n')) text[i] = '\n';
    const PlyHeader header = HeaderParser(text, path).parse();
    if (header.encoding == PlyEncoding::Ascii) return ContentLimit{};
    uint64_t total = header.data_offset;
    std::string parts = std::to_string(header.data_offset) + " header bytes";
    for (const PlyElement& e : header.elements) {
        bool fixed = true;
        const uint64_t per = max_element_bytes(e, fixed);
        if (per > 0 && e.count > (kMaxMeshFileBytes - total) / per) return ContentLimit{};  // beyond any file read: the reader says why
        total += e.count * per;
        parts += ", element '" + e.name + "' " + std::to_string(e.count) + " x " + (fixed ? "" : "at most ") +
                 std::to_string(per) + " bytes";
    }
    return ContentLimit{total, "what its binary PLY header declares: " + parts};
}

TriangleMesh read_ply(const std::string& bytes, const std::string& path) {
    const PlyHeader header = HeaderParser(bytes, path).parse();
    check_sizes(header, bytes, path);
    const PlyElement* vertex = nullptr;
    for (const PlyElement& e : header.elements) if (e.name == "vertex") vertex = &e;
    if (!vertex) throw_mesh_error(path, "PLY header", "no element 'vertex'");
    if (vertex->count > uint64_t(INT_MAX))
        throw_mesh_error(path, "PLY header", std::to_string(vertex->count) + " vertices; at most " + std::to_string(INT_MAX) + " are supported");

    TriangleMesh mesh;
    PlyValues values(bytes, header, path);
    Reader reader{header, values, path, mesh, vertex->count, vertex, {}};
    bool have_faces = false;
    for (const PlyElement& e : header.elements) {
        values.element_ = e.name;
        if (e.name == "vertex") reader.read_vertices(e);
        else if (e.name == "face") { reader.read_faces(e); have_faces = true; }
        else reader.skip(e);
    }
    if (!have_faces) throw_mesh_error(path, "PLY header", "no element 'face' (a point cloud has no surface)");
    if (values.trailing_data())
        throw_mesh_error(path, "PLY data (" + values.next_place() + ")",
                         "data continues after the last declared element (is a count in the header too small?)");
    check_finite_vertices(mesh, path);
    reader.polygons.triangulate_into(mesh);
    check_loaded_mesh(mesh, path, "PLY file");
    return mesh;
}

}  // namespace sdf
