#include "core/mesh/load_mesh.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>

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

bool first_token_is(const std::string& bytes, bool (*test)(std::string_view)) {
    TextCursor words(std::string_view(bytes).substr(0, 4096));
    std::string_view w;
    return words.next(w) && test(w);
}

bool is_ply_magic(std::string_view w) { return w == "ply"; }
bool is_off_magic(std::string_view w) { return w.size() >= 3 && w.size() <= 7 && w.substr(w.size() - 3) == "OFF"; }
bool is_solid(std::string_view w) { return w == "solid"; }

bool is_binary_stl(const std::string& bytes) {
    if (bytes.size() < 84) return false;
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);
    return bytes.size() == 84 + 50 * uint64_t(n);
}

/// An OBJ statement ("v ", "f ", "vn ", "o ", ...) starting one of the first lines.
bool looks_like_obj(const std::string& bytes) {
    TextCursor words(std::string_view(bytes).substr(0, 1 << 16));
    words.hash_comments = true;
    std::string_view w;
    return words.next(w) && (w == "v" || w == "vn" || w == "vt" || w == "f" || w == "o" || w == "g" || w == "mtllib" || w == "s");
}

}  // namespace

MeshFormat detect_mesh_format(const std::string& path, const std::string& bytes) {
    if (first_token_is(bytes, is_ply_magic)) return MeshFormat::Ply;
    if (first_token_is(bytes, is_off_magic)) return MeshFormat::Off;
    if (is_binary_stl(bytes)) return MeshFormat::Stl;
    const bool solid = first_token_is(bytes, is_solid);
    if (solid && bytes.find("facet", 0) != std::string::npos) return MeshFormat::Stl;
    const std::string ext = inner_extension(path);
    if (ext == "obj") return MeshFormat::Obj;
    if (ext == "ply") return MeshFormat::Ply;
    if (ext == "stl") return MeshFormat::Stl;
    if (ext == "off") return MeshFormat::Off;
    if (looks_like_obj(bytes)) return MeshFormat::Obj;
    throw std::runtime_error(path + ": unsupported mesh format " +
                             (ext.empty() ? std::string("(no extension, and the content is not recognised)")
                                          : "'" + ext + "' (by its extension; the content is not recognised either)") +
                             "; supported: OBJ, PLY (ascii and binary), STL (ascii and binary), OFF, each optionally .gz");
}

TriangleMesh load_mesh_file(const std::string& path) {
    MeshFileBytes file = read_mesh_file_bytes(path);
    // Editors put a byte-order mark before text (OBJ, ASCII PLY/STL, OFF); a binary STL's
    // 80-byte header may begin with anything, so it keeps its bytes.
    if (!is_binary_stl(file.bytes)) {
        reject_wide_encodings(file.bytes, path, "mesh file");
        const size_t bom = file.bytes.size() - without_utf8_bom(file.bytes).size();
        file.bytes.erase(0, bom);
    }
    const MeshFormat format = detect_mesh_format(path, file.bytes);
    TriangleMesh mesh;
    switch (format) {
        case MeshFormat::Obj: mesh = load_obj_text(file.bytes, path); break;
        case MeshFormat::Ply: mesh = read_ply(file.bytes, path); break;
        case MeshFormat::Stl: mesh = read_stl(file.bytes, path); break;
        case MeshFormat::Off: mesh = read_off(file.bytes, path); break;
    }
    mesh.name = name_of(path);
    mesh.source = path;
    mesh.content_sha256 = file.file_sha256;
    return mesh;
}

}  // namespace sdf
