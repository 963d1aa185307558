#include "core/mesh/mesh_file_bytes.h"

#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "core/io/text_file.h"
#include "core/mesh/sha256.h"

namespace sdf {
namespace {

std::string read_plain(const std::string& path, uint64_t size) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw_mesh_error(path, "", "cannot open mesh file");
    std::string bytes(size_t(size), '\0');
    if (!in.read(bytes.data(), std::streamsize(size)))
        throw_mesh_error(path, "", "cannot read " + std::to_string(size) + " bytes");
    return bytes;
}

/// gzread in growing chunks; the final size is unknown until the stream ends.
std::string read_gzip(const std::string& path) {
    gzFile file = gzopen(path.c_str(), "rb");
    if (!file) throw_mesh_error(path, "", "cannot open gzip file");
    std::string bytes;
    std::vector<char> chunk(size_t(1) << 20);
    for (;;) {
        const int got = gzread(file, chunk.data(), unsigned(chunk.size()));
        if (got < 0) {
            int code = 0;
            const std::string message = gzerror(file, &code);
            gzclose(file);
            throw_mesh_error(path, "", "corrupt gzip stream (" + message + ")");
        }
        if (got == 0) break;
        if (uint64_t(bytes.size()) + uint64_t(got) > kMaxMeshFileBytes) {
            gzclose(file);
            throw_mesh_error(path, "", "decompresses to more than " + std::to_string(kMaxMeshFileBytes) +
                                           " bytes (the largest mesh file read)");
        }
        bytes.append(chunk.data(), size_t(got));
    }
    // gzread returns 0 at a truncated end too; gzclose reports it as Z_BUF_ERROR.
    const int closed = gzclose(file);
    if (closed != Z_OK)
        throw_mesh_error(path, "", closed == Z_BUF_ERROR ? "truncated gzip stream" : "corrupt gzip stream");
    return bytes;
}

}  // namespace

MeshFileBytes read_mesh_file_bytes(const std::string& path) {
    namespace fs = std::filesystem;
    require_regular_file(path, "mesh file");
    const uint64_t size = fs::file_size(path);
    if (size > kMaxMeshFileBytes)
        throw_mesh_error(path, "", "file has " + std::to_string(size) + " bytes, more than the largest mesh file read (" +
                                       std::to_string(kMaxMeshFileBytes) + ")");
    MeshFileBytes out;
    out.bytes = read_plain(path, size);
    out.file_sha256 = sha256_hex(out.bytes.data(), out.bytes.size());
    out.gzip = out.bytes.size() >= 2 && uint8_t(out.bytes[0]) == 0x1f && uint8_t(out.bytes[1]) == 0x8b;
    if (out.gzip) out.bytes = read_gzip(path);
    return out;
}

size_t ExactVertexWelder::Hash::operator()(const Vec3d& p) const {
    // std::hash<double> maps -0 and +0 alike, matching ==.
    std::hash<double> h;
    return h(p.x) ^ (h(p.y) * 0x9e3779b97f4a7c15ull) ^ (h(p.z) * 0xc2b2ae3d27d4eb4full);
}

int ExactVertexWelder::id_of(const Vec3d& p) {
    const auto [it, inserted] = ids_.emplace(p, int(vertices_.size()));
    if (inserted) vertices_.push_back(p);
    return it->second;
}

void check_loaded_mesh(const TriangleMesh& mesh, const std::string& path, const std::string& what) {
    if (mesh.triangles.empty()) throw_mesh_error(path, "", what + " holds no triangles (no faces with 3 or more vertices)");
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
        const Vec3d& p = mesh.vertices[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw_mesh_error(path, "vertex " + std::to_string(i), "non-finite coordinate; expected three finite numbers");
    }
    const size_t n = mesh.vertices.size();
    for (size_t f = 0; f < mesh.triangles.size(); ++f)
        for (int k = 0; k < 3; ++k)
            if (mesh.triangles[f][k] < 0 || size_t(mesh.triangles[f][k]) >= n)
                throw_mesh_error(path, "triangle " + std::to_string(f),
                                 "refers to vertex " + std::to_string(mesh.triangles[f][k]) + ", but the file has " +
                                     std::to_string(n) + " vertices (0-based)");
}

}  // namespace sdf
