/// @file mesh_file_bytes.h
/// @brief The bytes of a mesh file, gunzipped when the file is gzip-compressed (zlib), and
/// the small helpers the format readers share: errors that name the file and the place,
/// exact vertex welding for formats that repeat vertices (STL).
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/mesh/triangle_mesh.h"

namespace sdf {

/// Largest decompressed mesh file read (bytes): a size check before allocation, so that a
/// gzip bomb or a corrupt stream ends with an error and not with the machine's memory.
constexpr uint64_t kMaxMeshFileBytes = uint64_t(16) << 30;

struct MeshFileBytes {
    std::string bytes;        ///< decompressed content
    bool gzip = false;        ///< the file was gzip-compressed
    std::string file_sha256;  ///< of the file's bytes as stored (compressed or not)
};

/// The most bytes a file's content may have, by what it declares, and why (for the message).
struct ContentLimit {
    uint64_t bytes = kMaxMeshFileBytes;
    std::string reason;  ///< e.g. "its binary STL header declares 2 triangles (84 + 50 x 2 bytes)"
};

/// What the content read so far allows, asked while a gzip file is decompressed (after
/// each megabyte, with the bytes so far and where the new ones begin): the most bytes the
/// whole content may have (e.g. a binary STL's or a binary PLY's declared size), or it
/// throws (e.g. a NUL byte in a text format). So a gzip bomb is refused after its first
/// megabyte, not after it has filled the memory.
using ContentCheck = std::function<ContentLimit(std::string_view so_far, size_t new_from)>;

/// Reads `path` whole, gunzipping it when it starts with the gzip magic (1f 8b), at most
/// kMaxMeshFileBytes and what `check` allows. Throws std::runtime_error naming the file
/// when it is missing, unreadable, a corrupt or truncated gzip stream, has data after the
/// stream, is larger than allowed once decompressed, or does not fit in memory.
MeshFileBytes read_mesh_file_bytes(const std::string& path, const ContentCheck& check = {});

/// A reader's error: "<path>: <where>: <what>", e.g. "a.ply: header line 3: ...".
[[noreturn]] inline void throw_mesh_error(const std::string& path, const std::string& where, const std::string& what) {
    throw std::runtime_error(path + (where.empty() ? "" : ": " + where) + ": " + what);
}

/// Merges vertices with equal coordinates (==, so -0 and +0 are one vertex) in order of
/// first appearance; STL lists every triangle's corners separately.
class ExactVertexWelder {
public:
    explicit ExactVertexWelder(std::vector<Vec3d>& vertices) : vertices_(vertices) {}
    int id_of(const Vec3d& p);

private:
    struct Hash {
        size_t operator()(const Vec3d& p) const;
    };
    std::vector<Vec3d>& vertices_;
    std::unordered_map<Vec3d, int, Hash> ids_;
};

/// Throws naming the first vertex with a non-finite coordinate.
void check_finite_vertices(const TriangleMesh& mesh, const std::string& path);

/// Checks the finished mesh as every reader must leave it: at least one triangle, every
/// index in range, every coordinate finite. `what` names the format in the message.
void check_loaded_mesh(const TriangleMesh& mesh, const std::string& path, const std::string& what);

}  // namespace sdf
