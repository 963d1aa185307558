#include "core/mesh/load_mesh.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <new>

#include "core/io/text_file.h"
#include "core/mesh/load_obj.h"
#include "core/mesh/mesh_file_bytes.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/text_cursor.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;

std::string lowercase(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

/// "dragon.PLY.gz" -> "ply"; "" without an extension.
std::string inner_extension(const std::string& path) {
    fs::path p(path);
    if (lowercase(p.extension().string()) == ".gz") p = p.stem();
    const std::string ext = lowercase(p.extension().string());
    return ext.empty() ? ext : ext.substr(1);
}

std::string name_of(const std::string& path) {
    fs::path p = fs::path(path).filename();
    if (lowercase(p.extension().string()) == ".gz") p = p.stem();
    return p.stem().string();
}

bool first_token_is(std::string_view bytes, bool (*test)(std::string_view)) {
    TextCursor words(bytes.substr(0, 4096));
    std::string_view w;
    return words.next(w) && test(w);
}

bool is_ply_magic(std::string_view w) { return w == "ply"; }
bool is_off_magic(std::string_view w) { return w.size() >= 3 && w.size() <= 7 && w.substr(w.size() - 3) == "OFF"; }

bool is_ply(std::string_view bytes) { return first_token_is(bytes, is_ply_magic); }
bool is_off(std::string_view bytes) { return first_token_is(bytes, is_off_magic); }

bool is_binary_stl(std::string_view bytes) {
    if (bytes.size() < 84) return false;
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);
    return bytes.size() == 84 + 50 * uint64_t(n);
}

bool is_stl(std::string_view bytes) { return is_binary_stl(bytes) || is_ascii_stl_start(bytes); }

/// An OBJ statement ("v ", "f ", "vn ", "o ", ...) starting one of the first lines.
bool looks_like_obj(std::string_view bytes) {
    TextCursor words(bytes.substr(0, 1 << 16));
    words.hash_comments = true;
    std::string_view w;
    return words.next(w) && (w == "v" || w == "vn" || w == "vt" || w == "f" || w == "o" || w == "g" || w == "mtllib" || w == "s");
}

/// The format whose row lists `extension`, or null.
const MeshFormatRow* format_by_extension(const std::string& extension) {
    for (const MeshFormatRow& row : mesh_formats())
        for (const char* e : row.extensions)
            if (e && extension == e) return &row;
    return nullptr;
}

/// The line (1-based) of byte `at`, for messages.
int64_t line_of(std::string_view bytes, size_t at) {
    return 1 + std::count(bytes.begin(), bytes.begin() + std::ptrdiff_t(std::min(at, bytes.size())), '\n');
}

/// What load_mesh_file() can tell from the content while it is still being read: a file
/// that holds binary data where every reader expects text is refused at once (a gzip of
/// zeros after its first megabyte), and a binary STL or binary PLY may not outgrow the size
/// its header declares.
ContentCheck content_check(const std::string& path) {
    return [path, named = format_by_extension(inner_extension(path)), ply_header_read = false](
               std::string_view so_far, size_t new_from) mutable -> ContentLimit {
        const size_t bom = so_far.size() - without_utf8_bom(so_far).size();
        if (first_token_is(so_far.substr(bom), is_ply_magic)) {
            // Text up to "end_header", binary data after it in binary PLY.
            if (ply_header_read) return {};
            const std::string_view header = so_far.substr(0, so_far.find("end_header"));
            if (const size_t nul = header.find('\0', new_from); nul != std::string_view::npos)
                throw_mesh_error(path, "PLY header line " + std::to_string(line_of(so_far, nul)),
                                 "byte " + std::to_string(nul) + " is a NUL byte; expected a text header");
            std::optional<ContentLimit> limit = ply_size_limit(so_far.substr(bom), path);
            if (!limit) return {};  // the header is not complete yet
            ply_header_read = true;
            limit->bytes += limit->bytes < kMaxMeshFileBytes ? bom : 0;
            return *limit;
        }
        const bool off = first_token_is(so_far.substr(bom), is_off_magic);
        // A binary STL unless the extension names another format.
        const bool named_stl = named && named->format == MeshFormat::Stl;
        if (!off && so_far.size() >= 84 && (!named || named_stl) &&
            (holds_binary_bytes(so_far) || (named_stl && !is_ascii_stl_start(so_far)))) {
            uint32_t n = 0;
            std::memcpy(&n, so_far.data() + 80, 4);
            return {84 + 50 * uint64_t(n), "what its binary STL header declares: " + std::to_string(n) +
                                               " triangles, 84 + 50 x " + std::to_string(n) + " bytes"};
        }
        if (new_from == 0) reject_wide_encodings(so_far, path, "mesh file");
        if (const size_t nul = so_far.find('\0', new_from); nul != std::string_view::npos)
            throw_mesh_error(path, "line " + std::to_string(line_of(so_far, nul)),
                             "byte " + std::to_string(nul) +
                                 " is a NUL byte; expected text (OBJ, OFF and ASCII STL are text): is the file binary, "
                                 "or UTF-16?");
        return {};
    };
}

/// Classic Mac OS line ends (a lone CR) become LF in place, so that every text reader
/// counts lines alike; `end` limits it to a binary PLY's text header.
void lone_cr_to_lf(std::string& bytes, size_t end) {
    end = std::min(end, bytes.size());
    for (size_t i = 0; i < end; ++i)
        if (bytes[i] == '\r' && (i + 1 == bytes.size() || bytes[i + 1] != '\n')) bytes[i] = '\n';
}

/// Where lone CRs may be line ends: all of a text format, a PLY's header (all of an ascii PLY).
size_t text_end(const std::string& bytes, MeshFormat format) {
    if (format == MeshFormat::Stl && !is_ascii_stl_start(bytes)) return 0;
    if (format != MeshFormat::Ply) return bytes.size();
    const size_t header_end = bytes.find("end_header");
    if (header_end == std::string::npos) return bytes.size();
    const bool ascii = std::string_view(bytes).substr(0, header_end).find("format ascii") != std::string_view::npos;
    return ascii ? bytes.size() : header_end + std::strlen("end_header") + 1;
}

}  // namespace

const std::vector<MeshFormatRow>& mesh_formats() {
    // Content is tested in this order: PLY's and OFF's magic lines before binary STL's exact
    // size, which a text file could match by chance.
    static const std::vector<MeshFormatRow> rows = {
        {MeshFormat::Obj, "OBJ", "", {"obj", nullptr}, nullptr, looks_like_obj, load_obj_text},
        {MeshFormat::Ply, "PLY", " (ascii and binary)", {"ply", nullptr}, is_ply, nullptr, read_ply},
        {MeshFormat::Off, "OFF", "", {"off", nullptr}, is_off, nullptr, read_off},
        {MeshFormat::Stl, "STL", " (ascii and binary)", {"stl", nullptr}, is_stl, nullptr, read_stl},
    };
    return rows;
}

const MeshFormatRow& mesh_format(MeshFormat format) {
    // No default: a MeshFormat without its case is a -Wswitch warning (an error in developer builds).
    size_t row = 0;
    switch (format) {
        case MeshFormat::Obj: row = 0; break;
        case MeshFormat::Ply: row = 1; break;
        case MeshFormat::Off: row = 2; break;
        case MeshFormat::Stl: row = 3; break;
    }
    return mesh_formats().at(row);
}

const char* mesh_format_name(MeshFormat format) { return mesh_format(format).name; }

std::string mesh_formats_help() {
    std::string s;
    for (const MeshFormatRow& row : mesh_formats()) s += std::string(s.empty() ? "" : ", ") + row.name;
    return s + ", optionally .gz";
}

std::string mesh_formats_supported() {
    std::string s;
    for (const MeshFormatRow& row : mesh_formats()) s += std::string(s.empty() ? "" : ", ") + row.name + row.variants;
    return s + ", each optionally .gz";
}

MeshFormat detect_mesh_format(const std::string& path, const std::string& bytes) {
    for (const MeshFormatRow& row : mesh_formats())
        if (row.definite && row.definite(bytes)) return row.format;
    const std::string ext = inner_extension(path);
    if (const MeshFormatRow* named = format_by_extension(ext)) return named->format;
    for (const MeshFormatRow& row : mesh_formats())
        if (row.likely && row.likely(bytes)) return row.format;
    throw std::runtime_error(path + ": unsupported mesh format " +
                             (ext.empty() ? std::string("(no extension, and the content is not recognised)")
                                          : "'" + ext + "' (by its extension; the content is not recognised either)") +
                             "; supported: " + mesh_formats_supported());
}

TriangleMesh load_mesh_file(const std::string& path) {
    MeshFileBytes file = read_mesh_file_bytes(path, content_check(path));
    // Editors put a byte-order mark before text (OBJ, ASCII PLY/STL, OFF); a binary STL's
    // 80-byte header may begin with anything, so it keeps its bytes.
    if (!is_binary_stl(file.bytes)) {
        reject_wide_encodings(file.bytes, path, "mesh file");
        const size_t bom = file.bytes.size() - without_utf8_bom(file.bytes).size();
        file.bytes.erase(0, bom);
    }
    const MeshFormat format = detect_mesh_format(path, file.bytes);
    lone_cr_to_lf(file.bytes, text_end(file.bytes, format));
    TriangleMesh mesh;
    try {
        mesh = mesh_format(format).read(file.bytes, path);
    } catch (const std::bad_alloc&) {
        throw_mesh_error(path, "", std::string("not enough memory to read the ") + mesh_format_name(format) + " mesh (" +
                                       std::to_string(file.bytes.size()) + " bytes" + (file.gzip ? " decompressed" : "") +
                                       ")");
    }
    mesh.name = name_of(path);
    mesh.source = path;
    mesh.content_sha256 = file.file_sha256;
    return mesh;
}

}  // namespace sdf
