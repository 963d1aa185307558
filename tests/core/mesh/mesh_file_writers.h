// Writers of the mesh formats for the tests, written from the format descriptions and
// independent of the readers under test: OBJ, PLY (ascii, binary little- and big-endian,
// with extra properties and elements the reader must skip), STL (ascii, binary), OFF, and
// gzip through zlib. Coordinates are written with 17 significant digits (round trip exact).
#pragma once

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/mesh/triangle_mesh.h"

namespace sdf::test {

inline std::string g17(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

inline std::string obj_text(const TriangleMesh& m) {
    std::string s = "# written by the test\n";
    for (const Vec3d& p : m.vertices) s += "v " + g17(p.x) + " " + g17(p.y) + " " + g17(p.z) + "\n";
    for (const Int3& t : m.triangles)
        s += "f " + std::to_string(t.x + 1) + " " + std::to_string(t.y + 1) + " " + std::to_string(t.z + 1) + "\n";
    return s;
}

inline std::string off_text(const TriangleMesh& m) {
    std::string s = "OFF\n# a comment\n" + std::to_string(m.vertices.size()) + " " + std::to_string(m.triangles.size()) + " 0\n";
    for (const Vec3d& p : m.vertices) s += g17(p.x) + " " + g17(p.y) + " " + g17(p.z) + "\n";
    for (const Int3& t : m.triangles)
        s += "3 " + std::to_string(t.x) + " " + std::to_string(t.y) + " " + std::to_string(t.z) + "\n";
    return s;
}

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };

/// Appends `v` in the file's byte order (the host is little-endian).
template <typename T>
void put(std::string& s, T v, bool big_endian) {
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    if (big_endian) std::reverse(raw, raw + sizeof(T));
    s.append(reinterpret_cast<const char*>(raw), sizeof(T));
}

/// PLY with vertices (x y z as double, or float when `float_vertices`, plus a uchar the
/// reader skips), an element "edge" it skips, and faces with a uchar count, int indices and
/// a trailing float list it skips.
inline std::string ply_text(const TriangleMesh& m, PlyEncoding e, bool float_vertices = false) {
    const char* format = e == PlyEncoding::Ascii ? "ascii" : e == PlyEncoding::BinaryLittleEndian ? "binary_little_endian" : "binary_big_endian";
    const char* coord = float_vertices ? "float" : "double";
    std::string s = std::string("ply\nformat ") + format + " 1.0\ncomment written by the test\n" +
                    "element vertex " + std::to_string(m.vertices.size()) + "\n" +
                    "property " + coord + " x\nproperty " + coord + " y\nproperty " + coord + " z\nproperty uchar quality\n" +
                    "element edge 1\nproperty int vertex1\nproperty int vertex2\n" +
                    "element face " + std::to_string(m.triangles.size()) + "\n" +
                    "property list uchar int vertex_indices\nproperty list uchar float texcoord\n" + "end_header\n";
    const bool big = e == PlyEncoding::BinaryBigEndian;
    for (const Vec3d& p : m.vertices) {
        if (e == PlyEncoding::Ascii) { s += g17(p.x) + " " + g17(p.y) + " " + g17(p.z) + " 7\n"; continue; }
        for (int k = 0; k < 3; ++k) {
            if (float_vertices) put<float>(s, float(p[k]), big);
            else put<double>(s, p[k], big);
        }
        put<uint8_t>(s, 7, big);
    }
    if (e == PlyEncoding::Ascii) s += "0 1\n";
    else { put<int32_t>(s, 0, big); put<int32_t>(s, 1, big); }
    for (const Int3& t : m.triangles) {
        if (e == PlyEncoding::Ascii) {
            s += "3 " + std::to_string(t.x) + " " + std::to_string(t.y) + " " + std::to_string(t.z) + " 2 0.5 0.25\n";
            continue;
        }
        put<uint8_t>(s, 3, big);
        for (int k = 0; k < 3; ++k) put<int32_t>(s, t[k], big);
        put<uint8_t>(s, 2, big);
        put<float>(s, 0.5f, big);
        put<float>(s, 0.25f, big);
    }
    return s;
}

inline Vec3d face_normal(const TriangleMesh& m, const Int3& t) {
    const Vec3d a = m.vertices[size_t(t.x)], b = m.vertices[size_t(t.y)], c = m.vertices[size_t(t.z)];
    return normalize_or_zero(cross(b - a, c - a));
}

inline std::string stl_ascii_text(const TriangleMesh& m) {
    std::string s = "solid test shape\n";
    for (const Int3& t : m.triangles) {
        const Vec3d n = face_normal(m, t);
        s += "  facet normal " + g17(n.x) + " " + g17(n.y) + " " + g17(n.z) + "\n    outer loop\n";
        for (int k = 0; k < 3; ++k) {
            const Vec3d& p = m.vertices[size_t(t[k])];
            s += "      vertex " + g17(p.x) + " " + g17(p.y) + " " + g17(p.z) + "\n";
        }
        s += "    endloop\n  endfacet\n";
    }
    return s + "endsolid test shape\n";
}

/// Binary STL whose 80-byte header starts with "solid", as many exporters write it.
inline std::string stl_binary_text(const TriangleMesh& m) {
    std::string s = "solid but binary";
    s.resize(80, ' ');
    put<uint32_t>(s, uint32_t(m.triangles.size()), false);
    for (const Int3& t : m.triangles) {
        const Vec3d n = face_normal(m, t);
        for (int k = 0; k < 3; ++k) put<float>(s, float(n[k]), false);
        for (int v = 0; v < 3; ++v)
            for (int k = 0; k < 3; ++k) put<float>(s, float(m.vertices[size_t(t[v])][k]), false);
        put<uint16_t>(s, 0, false);
    }
    return s;
}

/// `bytes` gzip-compressed into the file `path` (zlib's gzwrite).
inline void write_gzip(const std::string& path, const std::string& bytes) {
    gzFile f = gzopen(path.c_str(), "wb");
    gzwrite(f, bytes.data(), unsigned(bytes.size()));
    gzclose(f);
}

}  // namespace sdf::test
