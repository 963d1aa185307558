#include "core/mesh/mesh_file_bytes.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <new>
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

/// The gzip trailer's ISIZE (the last member's size mod 2^32): a guess of the decompressed
/// size, so that a single-member file under 4 GiB is decompressed into a buffer reserved
/// at its exact size, with no copy while it grows.
uint64_t gzip_size_hint(const std::string& compressed) {
    if (compressed.size() < 18) return 0;
    const auto* b = reinterpret_cast<const unsigned char*>(compressed.data() + compressed.size() - 4);
    return uint64_t(b[0]) | uint64_t(b[1]) << 8 | uint64_t(b[2]) << 16 | uint64_t(b[3]) << 24;
}

/// Inflates the gzip members in `compressed` (zlib, in memory), asking `check` after each
/// megabyte how much the content may grow to.
std::string gunzip(const std::string& compressed, const std::string& path, const ContentCheck& check) {
    z_stream z{};
    if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) throw_mesh_error(path, "", "cannot start gzip decompression");
    struct End { z_stream* z; ~End() { inflateEnd(z); } } end{&z};
    constexpr size_t kStep = size_t(1) << 20;     // the check's granularity
    constexpr size_t kMaxFeed = size_t(1) << 30;  // zlib counts in 32-bit unsigned
    ContentLimit limit{kMaxMeshFileBytes, "the largest mesh file read"};
    const uint64_t hint = gzip_size_hint(compressed);
    std::string out;
    size_t in_at = 0, have = 0, checked = 0;
    const auto over = [&] {
        throw_mesh_error(path, "", "decompresses to more than " + std::to_string(limit.bytes) + " bytes (" + limit.reason + ")");
    };
    for (;;) {
        if (have == out.size()) {
            // A megabyte more at a time (resize touches what it adds). Once the content check
            // has had its say (so the hint is not trusted before it has seen the first
            // megabyte), the capacity is reserved at the trailer's size plus one byte, and the
            // buffer stays within it: one byte of room lets zlib report the stream's end, and
            // growing past the reservation would reallocate at twice the size.
            const bool use_hint = checked > 0 && hint > 0 && hint <= limit.bytes;
            uint64_t next = std::min<uint64_t>(limit.bytes + 1, uint64_t(have) + kStep);
            if (use_hint && have <= hint) next = std::min<uint64_t>(next, hint + 1);
            const bool reserve = use_hint && out.capacity() < hint + 1;
            try {
                if (reserve) out.reserve(size_t(hint + 1));
                out.resize(size_t(next));
            } catch (const std::bad_alloc&) {
                throw_mesh_error(path, "", "not enough memory to decompress the mesh file: " + std::to_string(compressed.size()) +
                                               " bytes gzip-compressed, " + std::to_string(reserve ? hint : next) +
                                               " bytes decompressed (a buffer of that size could not be allocated)");
            }
        }
        const size_t feed = std::min(compressed.size() - in_at, kMaxFeed);
        z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + in_at));
        z.avail_in = uInt(feed);
        z.next_out = reinterpret_cast<Bytef*>(out.data() + have);
        z.avail_out = uInt(std::min(out.size() - have, std::min(kStep, kMaxFeed)));
        const uInt out_before = z.avail_out;
        const int code = inflate(&z, Z_NO_FLUSH);
        in_at += feed - z.avail_in;
        have += out_before - z.avail_out;
        if (code == Z_DATA_ERROR || code == Z_NEED_DICT)
            throw_mesh_error(path, "", std::string("corrupt gzip stream (") + (z.msg ? z.msg : "invalid data") + ")");
        if (code == Z_MEM_ERROR) throw std::bad_alloc();
        const bool stream_end = code == Z_STREAM_END;
        if (check && (have - checked >= kStep || stream_end)) {
            ContentLimit allowed = check(std::string_view(out.data(), have), checked);
            checked = have;
            if (allowed.bytes < limit.bytes) limit = std::move(allowed);
        }
        if (have > limit.bytes) over();
        if (stream_end) {
            if (in_at == compressed.size()) break;
            // Another member (concatenated .gz files), or data that does not belong to the stream.
            if (compressed.size() - in_at < 2 || uint8_t(compressed[in_at]) != 0x1f || uint8_t(compressed[in_at + 1]) != 0x8b)
                throw_mesh_error(path, "", "data after the end of the gzip stream (byte " + std::to_string(in_at) + " of " +
                                               std::to_string(compressed.size()) + ")");
            inflateReset(&z);
            continue;
        }
        if (code == Z_BUF_ERROR && in_at == compressed.size()) throw_mesh_error(path, "", "truncated gzip stream");
        if (code != Z_OK && code != Z_BUF_ERROR) throw_mesh_error(path, "", "corrupt gzip stream (zlib error " + std::to_string(code) + ")");
    }
    out.resize(have);
    return out;
}

}  // namespace

MeshFileBytes read_mesh_file_bytes(const std::string& path, const ContentCheck& check) {
    namespace fs = std::filesystem;
    require_regular_file(path, "mesh file");
    const uint64_t size = fs::file_size(path);
    if (size > kMaxMeshFileBytes)
        throw_mesh_error(path, "", "file has " + std::to_string(size) + " bytes, more than the largest mesh file read (" +
                                       std::to_string(kMaxMeshFileBytes) + ")");
    MeshFileBytes out;
    try {
        out.bytes = read_plain(path, size);
        out.file_sha256 = sha256_hex(out.bytes.data(), out.bytes.size());
        out.gzip = out.bytes.size() >= 2 && uint8_t(out.bytes[0]) == 0x1f && uint8_t(out.bytes[1]) == 0x8b;
        if (out.gzip) out.bytes = gunzip(out.bytes, path, check);
        else if (check) check(out.bytes, 0);
    } catch (const std::bad_alloc&) {
        throw_mesh_error(path, "", "not enough memory to read the mesh file (" + std::to_string(size) + " bytes" +
                                       (out.gzip ? ", gzip-compressed" : "") + ")");
    }
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

void check_finite_vertices(const TriangleMesh& mesh, const std::string& path) {
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
        const Vec3d& p = mesh.vertices[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw_mesh_error(path, "vertex " + std::to_string(i), "non-finite coordinate; expected three finite numbers");
    }
}

void check_loaded_mesh(const TriangleMesh& mesh, const std::string& path, const std::string& what) {
    if (mesh.triangles.empty()) throw_mesh_error(path, "", what + " holds no triangles (no faces with 3 or more vertices)");
    check_finite_vertices(mesh, path);
    const size_t n = mesh.vertices.size();
    for (size_t f = 0; f < mesh.triangles.size(); ++f)
        for (int k = 0; k < 3; ++k)
            if (mesh.triangles[f][k] < 0 || size_t(mesh.triangles[f][k]) >= n)
                throw_mesh_error(path, "triangle " + std::to_string(f),
                                 "refers to vertex " + std::to_string(mesh.triangles[f][k]) + ", but the file has " +
                                     std::to_string(n) + " vertices (0-based)");
}

}  // namespace sdf
