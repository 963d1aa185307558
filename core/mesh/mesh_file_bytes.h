/// @file mesh_file_bytes.h
/// @brief The bytes of a mesh file, gunzipped when the file is gzip-compressed (zlib), and
/// the small helpers the format readers share: errors that name the file and the place,
/// exact vertex welding for formats that repeat vertices (STL).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
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

/// Reads `path` whole, gunzipping it when it starts with the gzip magic (1f 8b).
/// Throws std::runtime_error naming the file when it is missing, unreadable, a corrupt or
/// truncated gzip stream, or larger than kMaxMeshFileBytes once decompressed.
MeshFileBytes read_mesh_file_bytes(const std::string& path);

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

/// Checks the finished mesh as every reader must leave it: at least one triangle, every
/// index in range, every coordinate finite. `what` names the format in the message.
void check_loaded_mesh(const TriangleMesh& mesh, const std::string& path, const std::string& what);

}  // namespace sdf
