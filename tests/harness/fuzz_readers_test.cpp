// A deterministic fuzz battery for every reader of outside input (issue 11): mesh files of
// every format (OBJ, ASCII and binary PLY and STL, OFF, gzip; polygon faces, ASCII STL in
// capitals and on one line, classic Mac line ends, gzip members: issue 26; polygons of
// 256+ corners and slivers of every size in every format: issue 38), points files (text and .npy),
// field headers (dense, and the sparse band's header and block ids: issue 35) and configs (read, validated and planned as by run-experiment --dry-run). Valid seed files
// are mutated with a fixed seed: bit flips, truncation, swapped and deleted tokens and lines,
// huge, negative, fractional and non-finite numbers, byte-order marks, CRLF, NUL bytes.
// Every input must either parse or throw one of the project's error types (std::runtime_error
// or std::invalid_argument, ConfigError included) with a message naming the file: never a
// crash (the test would die), never another exception type (a library's own, bad_alloc,
// length_error), never a nameless message. Meshes that load are prepared too. And the certified
// float search (issue 22) on fresh adversarial points (core/sampling/adversarial_cases.h,
// another fixed seed): bit for bit the double brute force. A hostile input per reader
// (truncated, or a count far beyond the file) gets a message naming the file, the place and
// what was expected.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <typeinfo>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/mesh/load_mesh.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/parallel/progress.h"
#include "core/sampling/adversarial_cases.h"
#include "harness/sampling/sampler_table.h"
#include "experiments/experiment_registry.h"
#include "harness/io/field_file.h"
#include "harness/io/sparse_field_file.h"
#include "harness/io/npy_file.h"
#include "harness/io/points_file.h"
#include "harness/runner/runner.h"
#include "harness_test_util.h"
#include "tests/core/mesh/mesh_file_writers.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;

/// Deterministic mutations of one valid input.
class Mutator {
public:
    explicit Mutator(uint64_t seed) : rng_(seed) {}

    std::string mutate(const std::string& seed_bytes) {
        std::string s = seed_bytes;
        const int rounds = 1 + int(pick(3));
        for (int r = 0; r < rounds; ++r) s = mutate_once(s);
        return s;
    }

private:
    size_t pick(size_t n) { return n == 0 ? 0 : size_t(rng_() % n); }

    /// [start, end) of whitespace-separated tokens.
    static std::vector<std::pair<size_t, size_t>> tokens(const std::string& s) {
        std::vector<std::pair<size_t, size_t>> t;
        for (size_t i = 0; i < s.size();) {
            while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
            const size_t start = i;
            while (i < s.size() && !std::isspace(static_cast<unsigned char>(s[i]))) ++i;
            if (i > start) t.emplace_back(start, i);
        }
        return t;
    }

    std::string mutate_once(std::string s) {
        static const char* const kNumbers[] = {"4294967297", "-4294967297", "2147483648",  "-2147483649",
                                               "99999999999999999999999", "1e400", "-1e400", "nan", "inf", "-inf",
                                               "-0", "0", "-1", "1.5", "1e-320", "9223372036854775807",
                                               "18446744073709551616", "0x10", "+", "-", "", "\"\"", "[]", "{}", "null"};
        const auto toks = tokens(s);
        switch (pick(11)) {
            case 0:  // bit flips
                for (int k = 0, n = 1 + int(pick(4)); k < n && !s.empty(); ++k) s[pick(s.size())] ^= char(1 << pick(8));
                return s;
            case 1:  // truncation
                return s.substr(0, pick(s.size() + 1));
            case 2:  // two tokens swapped
                if (toks.size() >= 2) {
                    auto a = toks[pick(toks.size())], b = toks[pick(toks.size())];
                    if (a.first > b.first) std::swap(a, b);
                    if (a.second <= b.first) {
                        const std::string ta = s.substr(a.first, a.second - a.first);
                        const std::string tb = s.substr(b.first, b.second - b.first);
                        s.replace(b.first, tb.size(), ta);
                        s.replace(a.first, ta.size(), tb);
                    }
                }
                return s;
            case 3:
            case 4:  // a token replaced by an extreme number or an empty value
                if (!toks.empty()) {
                    const auto t = toks[pick(toks.size())];
                    std::string replacement = kNumbers[pick(sizeof kNumbers / sizeof *kNumbers)];
                    // Keep JSON punctuation around numbers so that the value, not the syntax, is tested.
                    const std::string old = s.substr(t.first, t.second - t.first);
                    const size_t digit = old.find_first_of("0123456789");
                    if (digit != std::string::npos) {
                        const size_t end = old.find_last_of("0123456789.e") + 1;
                        replacement = old.substr(0, digit) + replacement + old.substr(end);
                    }
                    s.replace(t.first, t.second - t.first, replacement);
                }
                return s;
            case 5:  // a token deleted
                if (!toks.empty()) {
                    const auto t = toks[pick(toks.size())];
                    s.erase(t.first, t.second - t.first);
                }
                return s;
            case 6: {  // a line deleted or duplicated
                const size_t at = s.find('\n', pick(s.size() + 1));
                if (at == std::string::npos) return s;
                const size_t end = s.find('\n', at + 1);
                const std::string line = s.substr(at, (end == std::string::npos ? s.size() : end) - at);
                if (pick(2)) s.erase(at, line.size());
                else s.insert(at, line);
                return s;
            }
            case 7:  // UTF-8 byte-order mark
                return "\xEF\xBB\xBF" + s;
            case 8: {  // CRLF line ends
                std::string out;
                for (char c : s) out += c == '\n' ? std::string("\r\n") : std::string(1, c);
                return out;
            }
            case 9:  // UTF-16 byte-order mark, or a NUL byte
                if (pick(2)) return std::string("\xFF\xFE", 2) + s;
                s.insert(pick(s.size() + 1), 1, '\0');
                return s;
            default:  // a random byte inserted
                s.insert(pick(s.size() + 1), 1, char(pick(256)));
                return s;
        }
    }

    std::mt19937_64 rng_;
};

/// Runs `read` on every mutation of `seed_bytes` written to `path`; fails on any throw
/// that is not a project error naming the file. Returns {parsed, refused}.
template <typename Read>
std::pair<int, int> fuzz(const std::string& path, const std::string& seed_bytes, int count, uint64_t seed, Read read) {
    Mutator m(seed);
    int parsed = 0, refused = 0;
    const std::string name = fs::path(path).filename().string();
    EXPECT_NO_THROW(read(path, seed_bytes)) << "the seed itself must parse: " << path;
    for (int i = 0; i < count; ++i) {
        const std::string bytes = m.mutate(seed_bytes);
        try {
            read(path, bytes);
            ++parsed;
        } catch (const std::runtime_error& e) {
            ++refused;
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
                << "mutation " << i << " of " << name << ": the message does not name the file: " << e.what();
        } catch (const std::invalid_argument& e) {
            ++refused;
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
                << "mutation " << i << " of " << name << ": the message does not name the file: " << e.what();
        } catch (const std::exception& e) {
            ADD_FAILURE() << "mutation " << i << " of " << name << " threw a foreign exception ("
                          << typeid(e).name() << "): " << e.what();
        }
    }
    std::cout << name << ": " << count << " mutations, " << parsed << " parsed, " << refused << " refused\n";
    return {parsed, refused};
}

class FuzzReaders : public test::ScratchDirTest {
protected:
    FuzzReaders() : ScratchDirTest("sdf_fuzz_readers_test") {}
    static constexpr int kPerSeed = 300;

    /// Loads and prepares the mesh file `path` holding `bytes`.
    static void load_and_prepare(const std::string& path, const std::string& bytes) {
        test::write_file(path, bytes);
        MeshPreparationOptions o;
        o.detect_intersections = false;
        prepare_mesh(load_mesh_file(path), o);
    }
};

TEST_F(FuzzReaders, MeshFilesOfEveryFormat) {
    const TriangleMesh box = make_box({1.0, 0.5, 0.25});
    const std::vector<std::pair<std::string, std::string>> seeds = {
        {"m.obj", test::obj_text(box)},
        {"m.off", test::off_text(box)},
        {"a.ply", test::ply_text(box, test::PlyEncoding::Ascii)},
        {"le.ply", test::ply_text(box, test::PlyEncoding::BinaryLittleEndian)},
        {"be.ply", test::ply_text(box, test::PlyEncoding::BinaryBigEndian, true)},
        {"a.stl", test::stl_ascii_text(box)},
        {"b.stl", test::stl_binary_text(box)},
    };
    int total = 0;
    for (size_t k = 0; k < seeds.size(); ++k) {
        const auto [parsed, refused] = fuzz(at(seeds[k].first), seeds[k].second, kPerSeed, 1000 + k, load_and_prepare);
        EXPECT_GT(refused, 0) << seeds[k].first;
        total += parsed + refused;
    }
    // gzip: mutations of the compressed stream (corrupt and truncated streams).
    test::write_gzip(at("z.obj.gz"), test::obj_text(box));
    const std::string gz = test::read_text(at("z.obj.gz"));
    total += fuzz(at("z.obj.gz"), gz, kPerSeed / 3, 2000, load_and_prepare).second > 0;
    EXPECT_GE(total, int(seeds.size()) * kPerSeed);
}

/// An L-shaped prism with concave hexagon caps and quad sides, as polygon faces in OBJ, OFF
/// or ASCII PLY: the seeds of the shared polygon triangulation (polygon_triangulation.h).
std::string polygon_prism(const std::string& format) {
    const double ring[6][2] = {{2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}, {0, 0}};
    std::vector<std::vector<int>> faces = {{0, 5, 4, 3, 2, 1}, {6, 7, 8, 9, 10, 11}};
    for (int k = 0; k < 6; ++k) faces.push_back({k, (k + 1) % 6, 6 + (k + 1) % 6, 6 + k});
    std::string vertices, polygons;
    for (int z = 0; z < 2; ++z)
        for (const auto& xy : ring)
            vertices += (format == "obj" ? "v " : "") + std::to_string(xy[0]) + " " + std::to_string(xy[1]) + " " +
                        std::to_string(z) + "\n";
    for (const auto& f : faces) {
        polygons += format == "obj" ? "f" : std::to_string(f.size());
        for (int i : f) polygons += " " + std::to_string(format == "obj" ? i + 1 : i);
        polygons += "\n";
    }
    if (format == "obj") return vertices + polygons;
    if (format == "off") return "OFF\n12 8 0\n" + vertices + polygons;
    return "ply\nformat ascii 1.0\nelement vertex 12\nproperty double x\nproperty double y\nproperty double z\n"
           "element face 8\nproperty list uchar int vertex_indices\nend_header\n" + vertices + polygons;
}

// The reader rules of issue 26: polygons, ASCII STL in capitals or on one line, classic Mac
// line ends, a binary STL whose header begins with "solid", gzip members, a .ply.gz bounded
// by its header.
TEST_F(FuzzReaders, MeshFilesUnderTheReaderRules) {
    const TriangleMesh box = make_box({1.0, 0.5, 0.25});
    std::string upper = test::stl_ascii_text(box);
    for (char& c : upper) c = char(std::toupper(static_cast<unsigned char>(c)));
    std::string one_line = test::stl_ascii_text(box);
    for (char& c : one_line) c = c == '\n' ? ' ' : c;
    std::string cr = test::off_text(box);
    for (char& c : cr) c = c == '\n' ? '\r' : c;
    const std::vector<std::pair<std::string, std::string>> seeds = {
        {"p.obj", polygon_prism("obj")}, {"p.off", polygon_prism("off")}, {"p.ply", polygon_prism("ply")},
        {"upper.stl", upper}, {"line.stl", one_line}, {"cr.off", cr}, {"solid.stl", test::stl_binary_text(box)},
    };
    for (size_t k = 0; k < seeds.size(); ++k) {
        const auto [parsed, refused] = fuzz(at(seeds[k].first), seeds[k].second, kPerSeed, 7000 + k, load_and_prepare);
        EXPECT_GT(refused, 0) << seeds[k].first;
    }
    test::write_gzip(at("a.gz"), polygon_prism("ply").substr(0, 100));
    test::write_gzip(at("b.gz"), polygon_prism("ply").substr(100));
    const std::string members = test::read_text(at("a.gz")) + test::read_text(at("b.gz"));
    fuzz(at("m.ply.gz"), members, kPerSeed / 3, 7100, load_and_prepare);
    // A binary PLY gzip-compressed after each mutation: its header's declared sizes bound the
    // decompression (mutated counts and types included).
    fuzz(at("g.ply.gz"), test::ply_text(box, test::PlyEncoding::BinaryLittleEndian), kPerSeed / 3, 7200,
         [](const std::string& path, const std::string& bytes) {
             test::write_gzip(path, bytes);
             MeshPreparationOptions o;
             o.detect_intersections = false;
             prepare_mesh(load_mesh_file(path), o);
         });
}

/// A prism over a convex polygon of n corners (n > 255: beyond a uchar count and
/// tinyobjloader's unsigned char), as OBJ, OFF, ASCII or binary PLY (list counts "uint") or
/// ASCII STL with polygon facets.
std::string wide_polygon_prism(const std::string& format, int n) {
    std::vector<Vec3d> v;
    for (int z = 0; z < 2; ++z)
        for (int k = 0; k < n; ++k)
            v.push_back({std::cos(6.283185307179586 * k / n), std::sin(6.283185307179586 * k / n), double(z)});
    std::vector<std::vector<int>> faces;
    std::vector<int> bottom, top;
    for (int k = 0; k < n; ++k) {
        bottom.push_back((n - k) % n);
        top.push_back(n + k);
        faces.push_back({k, (k + 1) % n, n + (k + 1) % n, n + k});
    }
    faces.push_back(bottom);
    faces.push_back(top);
    std::string s;
    if (format == "stl") {
        s = "solid wide\n";
        for (const auto& f : faces) {
            s += "facet normal 0 0 0\nouter loop\n";
            for (int i : f) s += "vertex " + test::g17(v[size_t(i)].x) + " " + test::g17(v[size_t(i)].y) + " " + test::g17(v[size_t(i)].z) + "\n";
            s += "endloop\nendfacet\n";
        }
        return s + "endsolid wide\n";
    }
    const bool binary = format == "binary ply";
    if (format == "off") s = "OFF\n" + std::to_string(v.size()) + " " + std::to_string(faces.size()) + " 0\n";
    if (format == "ply" || binary)
        s = std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") + " 1.0\nelement vertex " +
            std::to_string(v.size()) + "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
            std::to_string(faces.size()) + "\nproperty list uint int vertex_indices\nend_header\n";
    for (const Vec3d& p : v) {
        if (binary) for (int k = 0; k < 3; ++k) test::put<double>(s, p[k], false);
        else s += (format == "obj" ? "v " : "") + test::g17(p.x) + " " + test::g17(p.y) + " " + test::g17(p.z) + "\n";
    }
    for (const auto& f : faces) {
        if (binary) {
            test::put<uint32_t>(s, uint32_t(f.size()), false);
            for (int i : f) test::put<int32_t>(s, i, false);
            continue;
        }
        s += format == "obj" ? "f" : std::to_string(f.size());
        for (int i : f) s += " " + std::to_string(format == "obj" ? i + 1 : i);
        s += "\n";
    }
    return s;
}

// Issue 38: polygons of 256 and 300 corners in every format (OBJ's were cut modulo 256, an
// OFF cap on the last line was refused as truncated). The seeds read whole: 2n + 2(n - 2)
// triangles.
TEST_F(FuzzReaders, PolygonsOfMoreThan255CornersInEveryFormat) {
    const std::vector<std::pair<std::string, std::string>> formats = {
        {"w.obj", "obj"}, {"w.off", "off"}, {"w.ply", "ply"}, {"wb.ply", "binary ply"}, {"w.stl", "stl"}};
    for (size_t k = 0; k < formats.size(); ++k)
        for (const int n : {256, 300}) {
            const std::string seed = wide_polygon_prism(formats[k].second, n);
            const std::string path = at(std::to_string(n) + formats[k].first);
            test::write_file(path, seed);
            EXPECT_EQ(load_mesh_file(path).triangles.size(), size_t(2 * n + 2 * (n - 2))) << path;
            const auto [parsed, refused] = fuzz(path, seed, kPerSeed / 3, 9000 + 10 * k + size_t(n), load_and_prepare);
            EXPECT_GT(refused, 0) << path;
        }
}

/// Slivers of every size (make_sliver_zoo: needles and caps of 1e-2 .. 1e-8 degrees beside
/// their neighbours) and issue 38's sliver beside a wide triangle, with points on and around
/// them.
AdversarialCase sliver_seed_mesh() {
    AdversarialCase c = make_sliver_zoo(1.0, 38, 20);
    const int base = int(c.mesh.vertices.size());
    const Vec3d o{0, 10, 0};
    for (const Vec3d& v : std::vector<Vec3d>{{0, 0, 0}, {100, 0.436, 0}, {0, 5, 0}, {100, -0.436, 0}}) c.mesh.vertices.push_back(o + v);
    c.mesh.triangles.push_back({base, base + 1, base + 2});
    c.mesh.triangles.push_back({base, base + 3, base + 1});
    for (const Vec3d& p : std::vector<Vec3d>{{66, 0, 0}, {50, 0.1, 0}, {66, 0, -1}, {99, 0, 0.01}}) c.points.push_back(o + p);
    return c;
}

// Issue 38: slivers in every format. Each seed reads back as written (the text and double
// formats bit for bit; STL's float32 corners to their triangle count), every search of the
// mesh read (brute force and BVH, double and the certified float) finds the double brute
// force's triangle and distance at every point on and around the slivers, and mutations of
// each seed parse or are refused naming the file.
TEST_F(FuzzReaders, SliversInEveryFormat) {
    const AdversarialCase c = sliver_seed_mesh();
    const std::vector<std::pair<std::string, std::string>> seeds = {
        {"s.obj", test::obj_text(c.mesh)},
        {"s.off", test::off_text(c.mesh)},
        {"a_s.ply", test::ply_text(c.mesh, test::PlyEncoding::Ascii)},
        {"le_s.ply", test::ply_text(c.mesh, test::PlyEncoding::BinaryLittleEndian)},
        {"be_s.ply", test::ply_text(c.mesh, test::PlyEncoding::BinaryBigEndian)},
        {"a_s.stl", test::stl_ascii_text(c.mesh)},
        {"b_s.stl", test::stl_binary_text(c.mesh)},
    };
    for (size_t k = 0; k < seeds.size(); ++k) {
        const std::string path = at(seeds[k].first);
        test::write_file(path, seeds[k].second);
        const TriangleMesh read = load_mesh_file(path);
        ASSERT_EQ(read.triangles.size(), c.mesh.triangles.size()) << path;
        if (path.find(".stl") == std::string::npos) {
            ASSERT_EQ(read.vertices.size(), c.mesh.vertices.size()) << path;
            for (size_t i = 0; i < read.vertices.size(); ++i)
                ASSERT_TRUE(read.vertices[i] == c.mesh.vertices[i]) << path << ": vertex " << i;
            for (size_t i = 0; i < read.triangles.size(); ++i) ASSERT_EQ(read.triangles[i], c.mesh.triangles[i]) << path;
        }
        MeshPreparationOptions prep;
        prep.detect_intersections = false;
        const PreparedMesh mesh = prepare_mesh(read, prep);
        SamplerOptions o;
        o.backend = "cpu";
        o.method = "brute_force";
        o.precision = Precision::Double;
        o.progress = false;
        const std::vector<PointSample> want = make_sampler(o)->bind(share(mesh))->query(c.points);
        for (const Precision precision : {Precision::Double, Precision::Float})
            for (const char* method : {"brute_force", "bvh"}) {
                o.precision = precision;
                o.method = method;
                const std::vector<PointSample> got = make_sampler(o)->bind(share(mesh))->query(c.points);
                for (size_t i = 0; i < got.size(); ++i)
                    ASSERT_TRUE(got[i].triangle == want[i].triangle && got[i].distance == want[i].distance)
                        << path << " " << method << (precision == Precision::Float ? " float" : " double") << " point " << i
                        << ": " << got[i].distance << " (triangle " << got[i].triangle << "), want " << want[i].distance
                        << " (triangle " << want[i].triangle << ")";
            }
        const auto [parsed, refused] = fuzz(path, seeds[k].second, kPerSeed / 3, 9500 + k, load_and_prepare);
        EXPECT_GT(refused, 0) << path;
    }
}

/// What `read` throws for `bytes` written to `path` (a project error), or "" with a failure.
template <typename Read>
std::string refusal_of(const std::string& path, const std::string& bytes, Read read) {
    test::write_file(path, bytes);
    try {
        read(path);
    } catch (const std::runtime_error& e) {
        return e.what();
    } catch (const std::invalid_argument& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << path << ": a foreign exception (" << typeid(e).name() << "): " << e.what();
        return "";
    }
    ADD_FAILURE() << path << ": read without a word";
    return "";
}

/// A .npy header of `shape_text` ("(4, 3)") over `data_bytes` zero bytes of float64.
std::string npy_with_shape(const std::string& shape_text, size_t data_bytes) {
    std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': " + shape_text + ", }";
    while ((10 + dict.size() + 1) % 64 != 0) dict += ' ';
    dict += '\n';
    std::string s = "\x93NUMPY\x01";
    s += '\0';
    s += char(dict.size() & 0xff);
    s += char(dict.size() >> 8);
    return s + dict + std::string(data_bytes, '\0');
}

// A hostile input per reader, truncated or with a count far beyond the file: each is refused
// before anything of that size is allocated (the sanitizer build would fail on the
// allocation), with a message naming the file, the place (line, element or key) and what was
// expected or found.
TEST_F(FuzzReaders, HostileInputsGetAClearMessage) {
    const TriangleMesh box = make_box({1.0, 0.5, 0.25});
    const auto mesh = [](const std::string& path) { load_mesh_file(path); };
    struct Hostile {
        std::string name, bytes;
        std::vector<std::string> says;  ///< phrases the message must hold (besides the file's name)
    };
    std::string obj = test::obj_text(box);
    std::string off = test::off_text(box);
    std::string stl = test::stl_ascii_text(box);
    std::string stl_binary = test::stl_binary_text(box);
    std::string ply_binary = test::ply_text(box, test::PlyEncoding::BinaryLittleEndian);
    std::string stl_count = stl_binary;
    for (int k = 0; k < 4; ++k) stl_count[size_t(80 + k)] = '\xff';  // 4,294,967,295 triangles
    std::string ply_count = test::ply_text(box, test::PlyEncoding::Ascii);
    ply_count.replace(ply_count.find("element vertex 8"), 16, "element vertex 2000000000");
    const std::vector<Hostile> meshes = {
        {"cut.obj", obj.substr(0, obj.find("\nv ", obj.find("\nv ") + 1) + 6), {"cut.obj:3:", "expected three finite numbers after 'v'"}},
        {"index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4294967297\n", {"index.obj:4:", "refers to vertex 4294967297, but the file has 3 vertices"}},
        {"cut.off", off.substr(0, off.rfind('\n', off.rfind('\n', off.size() - 2) - 1) + 1), {"OFF line 21", "file ends after 10 of 12 faces", "truncated?"}},
        {"count.off", "OFF\n2000000000 2000000000 0\n0 0 0\n1 0 0\n", {"OFF line 2", "declares 2000000000 vertices and 2000000000 faces, more than the file's remaining 12 bytes hold"}},
        {"polygon.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n", {"OFF line 6", "face 0 declares 2000000000 vertices, more than its line holds"}},
        {"cut.ply", ply_binary.substr(0, ply_binary.size() - 7), {"PLY element 'face' 11", "list 'texcoord' declares 2 items", "truncated"}},
        {"count.ply", ply_count, {"PLY header", "need at least 16000000052 bytes", "only 349 follow"}},
        {"cut.stl", stl.substr(0, stl.size() / 2), {"ASCII STL line 43", "expected 'endfacet', found 'endfac'"}},
        {"end.stl", stl.substr(0, stl.rfind("endsolid")), {"ASCII STL", "without 'endsolid' (truncated?)"}},
        {"count.stl", stl_count, {"binary STL header", "declares 4294967295 triangles, which take 214748364834 bytes, but the file has 684"}},
    };
    for (const Hostile& h : meshes) {
        const std::string msg = refusal_of(at(h.name), h.bytes, mesh);
        std::cout << h.name << ": " << msg << "\n";
        EXPECT_TRUE(test::Contains(msg, h.name)) << msg;
        for (const std::string& phrase : h.says) EXPECT_TRUE(test::Contains(msg, phrase)) << h.name << ": " << msg << "\nlacks: " << phrase;
    }
    const auto points = [](const std::string& path) { read_points_file(path); };
    const std::vector<Hostile> point_files = {
        {"cut.txt", "0 0 0\n1 2 3\n4 5", {"cut.txt:3:", "expected three finite numbers", "'4 5'"}},
        {"cut.npy", npy_with_shape("(4, 3)", 40), {"needs 96 bytes of data; the file has 40"}},
        {"count.npy", npy_with_shape("(4000000000000, 3)", 96), {"shape (4000000000000, 3)", "needs 96000000000000 bytes"}},
    };
    for (const Hostile& h : point_files) {
        const std::string msg = refusal_of(at(h.name), h.bytes, points);
        std::cout << h.name << ": " << msg << "\n";
        EXPECT_TRUE(test::Contains(msg, h.name)) << msg;
        for (const std::string& phrase : h.says) EXPECT_TRUE(test::Contains(msg, phrase)) << h.name << ": " << msg << "\nlacks: " << phrase;
    }
    // A field header whose lattice is far larger than its channels, and a channel cut short.
    SampledField f;
    f.lattice.type = LatticeType::CC;
    f.lattice.spacing = 0.5;
    f.lattice.resolution = {3, 3, 3};
    for (int64_t i = 0; i < f.lattice.num_points(); ++i) f.distance.push_back(double(i));
    write_field(at("big.json"), f);
    std::string header = test::read_text(at("big.json"));
    const size_t resolution = header.find("\"resolution\"");
    ASSERT_NE(resolution, std::string::npos) << header;
    header.replace(resolution, header.find(']', resolution) + 1 - resolution, "\"resolution\": [100000, 100000, 100000]");
    const auto field = [](const std::string& path) { read_field(path); };
    std::string msg = refusal_of(at("big.json"), header, field);
    std::cout << "big.json: " << msg << "\n";
    EXPECT_TRUE(test::Contains(msg, "big.json")) << msg;
    EXPECT_TRUE(test::Contains(msg, "lattice.resolution")) << msg;
    EXPECT_TRUE(test::Contains(msg, "1000000000000000 points")) << msg;
    write_field(at("cut.json"), f);
    const std::string channel = test::read_text(at("cut.distance.raw"));
    test::write_file(at("cut.distance.raw"), channel.substr(0, channel.size() / 2));
    msg = refusal_of(at("cut.json"), test::read_text(at("cut.json")), field);
    std::cout << "cut.json: " << msg << "\n";
    EXPECT_TRUE(test::Contains(msg, "cut.distance.raw")) << msg;
    EXPECT_TRUE(test::Contains(msg, "holds " + std::to_string(channel.size() / 2) + " bytes")) << msg;
    EXPECT_TRUE(test::Contains(msg, "need " + std::to_string(channel.size()))) << msg;
}

TEST_F(FuzzReaders, PointsFiles) {
    const std::string seed = "# points\n0 0 0\n\n0.5 -1 2.25\n1e-3 4 5\n";
    const auto [parsed, refused] = fuzz(at("p.txt"), seed, kPerSeed, 3000, [](const std::string& path, const std::string& bytes) {
        test::write_file(path, bytes);
        read_points_file(path);
    });
    EXPECT_GT(parsed, 0);
    EXPECT_GT(refused, 0);
}

TEST_F(FuzzReaders, NpyFiles) {
    // Points (N, 3) in each dtype, read as sdf-query and sdf-eval read them, and as arrays.
    const std::vector<double> d = {0, 0, 0, 0.5, -1, 2.25, 1e-3, 4, 5, 7, 8, 9};
    const std::vector<float> f(d.begin(), d.end());
    const std::vector<int32_t> i = {0, 1, 2, 3, -4, 5};
    const std::vector<int64_t> l = {1, 2, 3};
    const std::vector<std::pair<std::string, std::string>> seeds = {
        {"d.npy", npy_bytes(NpyDtype::Float64, {4, 3}, d.data())},
        {"f.npy", npy_bytes(NpyDtype::Float32, {4, 3}, f.data())},
        {"i.npy", npy_bytes(NpyDtype::Int32, {2, 3}, i.data())},
        {"l.npy", npy_bytes(NpyDtype::Int64, {1, 3}, l.data())},
    };
    int parsed = 0, refused = 0;
    for (size_t k = 0; k < seeds.size(); ++k) {
        const auto [p, r] = fuzz(at(seeds[k].first), seeds[k].second, kPerSeed / 2, 6000 + k,
                                 [](const std::string& path, const std::string& bytes) {
                                     test::write_file(path, bytes);
                                     const NpyArray a = read_npy(path);
                                     EXPECT_EQ(a.data.size(), size_t(a.count()) * size_t(npy_item_size(a.dtype)));
                                     read_points_file(path);
                                 });
        parsed += p;
        refused += r;
    }
    EXPECT_GT(parsed, 0);
    EXPECT_GT(refused, 0);
}

TEST_F(FuzzReaders, FieldHeaders) {
    // CC 3x3x3, one float32 value channel and a float32 gradient channel.
    SampledField f;
    f.lattice.type = LatticeType::CC;
    f.lattice.spacing = 0.5;
    f.lattice.resolution = {3, 3, 3};
    for (int64_t i = 0; i < f.lattice.num_points(); ++i) {
        f.distance.push_back(double(i) * 0.25 - 3);
        f.gradient.push_back({1, 0, 0});
    }
    // The typed records (sampler_report.h, mesh_provenance.h), so mutations reach their readers.
    f.sampler.backend = "cpu";
    f.sampler.method = "bvh";
    f.sampler.kernel = "brick";
    f.sampler.precision = "float";
    f.sampler.points_computed = 20;
    f.sampler.band = BandReport{0.5, 20, 7, "bricks skipped by the distance bound", true, 3, 1, 7};
    f.sampler.search_certificate = CertificateReport{true, "", true, 20, 2, 0};
    f.mesh.name = "fuzz";
    f.mesh.sha256 = "00ff";
    f.mesh.has_bounds = true;
    f.mesh.report = {{"components", 1}};
    FieldWriteOptions o;
    write_field(at("f.json"), f, o);
    const std::string seed = test::read_text(at("f.json"));
    const auto [parsed, refused] = fuzz(at("f.json"), seed, kPerSeed, 4000, [](const std::string& path, const std::string& bytes) {
        test::write_file(path, bytes);
        read_field(path);
    });
    EXPECT_GT(parsed, 0);
    EXPECT_GT(refused, 0);
}

// The sparse band's field file (sparse_field_file.h): its header, and its active block ids
// (binary: truncated, flipped, reordered), each read back and densified when it parses.
TEST_F(FuzzReaders, SparseFieldHeadersAndBlockIds) {
    Lattice l;
    l.type = LatticeType::BCC;
    l.spacing = 0.5;
    l.resolution = {20, 10, 9};
    SparseBandField band(l, 0.75, Precision::Float);
    for (int64_t id : {1, 4, 9}) {
        const size_t base = size_t(band.add_active(id)) * kBandBlockPoints;
        for (int local = 0; local < kBandBlockPoints; local += 3) {
            if (band.layout().storage_index(id, local) < 0) continue;  // padding holds +W
            band.distance.set(base + size_t(local), 0.001 * local - 0.3);  // |d| <= W: a band point
            band.gradient[base + size_t(local)] = {0, 0, 1};
            band.closest_triangle[base + size_t(local)] = local % 5;
        }
    }
    band.mask_from_triangles();
    band.mixed_inside[size_t(band.add_mixed(6))][2] = 0xF0F0;
    band.set_tile_inside(7, true);
    band.set_tile_inside(int(band.layout().block_count()) - 1, true);
    band.sampler.backend = "cpu";
    band.sampler.band = BandReport{0.75, 20, 7, "bricks", true, 3, 1, 7};
    band.mesh.name = "fuzz";
    write_sparse_field(at("s.json"), band);
    const auto read_back = [](const std::string& path) {
        const SparseBandField b = read_sparse_field(path);
        b.densify();
        b.counts();
    };
    const std::string seed = test::read_text(at("s.json"));
    const auto [parsed, refused] = fuzz(at("s.json"), seed, kPerSeed, 4100, [&](const std::string& path, const std::string& bytes) {
        test::write_file(path, bytes);
        read_back(path);
    });
    EXPECT_GT(parsed, 0);
    EXPECT_GT(refused, 0);
    test::write_file(at("s.json"), seed);
    const std::string ids_path = at("s.active_blocks.raw"), ids = test::read_text(ids_path);
    int id_refused = 0;
    Mutator m(4200);
    for (int i = 0; i < kPerSeed; ++i) {
        test::write_file(ids_path, m.mutate(ids));
        try {
            read_back(at("s.json"));
        } catch (const std::runtime_error& e) {
            ++id_refused;
            EXPECT_NE(std::string(e.what()).find("s.json"), std::string::npos) << e.what();
        } catch (const std::invalid_argument& e) {
            ++id_refused;
            EXPECT_NE(std::string(e.what()).find("s.json"), std::string::npos) << e.what();
        } catch (const std::exception& e) {
            ADD_FAILURE() << "block ids mutation " << i << " threw a foreign exception (" << typeid(e).name() << "): " << e.what();
        }
    }
    std::cout << "s.active_blocks.raw: " << kPerSeed << " mutations, " << id_refused << " refused\n";
    EXPECT_GT(id_refused, 0);
}

// A sparse band's file without closest triangles: its band points as a mask ("band_points",
// 8 words per active block). Its header, and the mask's bytes (truncated, flipped: a bit on a
// padding point is refused), each read back, counted and densified when it parses.
TEST_F(FuzzReaders, SparseFieldBandPointsMask) {
    Lattice l;
    l.type = LatticeType::CC;
    l.spacing = 0.5;
    l.resolution = {20, 10, 9};  // blocks beyond x 16, y 8, z 8 hold padding
    BandChannels channels;
    channels.gradient = false;
    channels.closest_triangle = false;
    SparseBandField band(l, 0.75, Precision::Float, channels);
    for (int64_t id : {0, 5, 11}) {
        const size_t a = size_t(band.add_active(id));
        for (int local = 0; local < kBandBlockPoints; local += 3) {
            if (band.layout().storage_index(id, local) < 0) continue;
            band.distance.set(a * kBandBlockPoints + size_t(local), 0.001 * local - 0.3);  // |d| <= W: a band point
            set_mask_bit(band.band_mask[a], local);
        }
    }
    band.mixed_inside[size_t(band.add_mixed(6))][2] = 0xF0F0;
    band.set_tile_inside(7, true);
    SparseFieldWriteOptions o;
    o.gradient = false;
    write_sparse_field(at("m.json"), band, o);
    const auto read_back = [](const std::string& path) {
        const SparseBandField b = read_sparse_field(path);
        b.densify();
        b.counts();
    };
    read_back(at("m.json"));
    const std::string seed = test::read_text(at("m.json"));
    const auto [parsed, refused] = fuzz(at("m.json"), seed, kPerSeed, 4300, [&](const std::string& path, const std::string& bytes) {
        test::write_file(path, bytes);
        read_back(path);
    });
    EXPECT_GT(parsed, 0);
    EXPECT_GT(refused, 0);
    test::write_file(at("m.json"), seed);
    const std::string mask_path = at("m.band_points.raw"), mask = test::read_text(mask_path);
    ASSERT_EQ(mask.size(), 3u * 64u);
    int mask_refused = 0, mask_parsed = 0;
    Mutator m(4400);
    for (int i = 0; i < kPerSeed; ++i) {
        test::write_file(mask_path, m.mutate(mask));
        try {
            read_back(at("m.json"));
            ++mask_parsed;
        } catch (const std::runtime_error& e) {
            ++mask_refused;
            EXPECT_NE(std::string(e.what()).find("m.json"), std::string::npos) << e.what();
        } catch (const std::exception& e) {
            ADD_FAILURE() << "band_points mutation " << i << " threw a foreign exception (" << typeid(e).name() << "): " << e.what();
        }
    }
    std::cout << "m.band_points.raw: " << kPerSeed << " mutations, " << mask_parsed << " parsed, " << mask_refused << " refused\n";
    EXPECT_GT(mask_refused, 0);
}

TEST_F(FuzzReaders, ConfigsReadValidatedAndPlanned) {
    ProgressReporter::set_globally_enabled(false);
    const std::string seed = R"({
  "name": "fuzz",
  "kind": "reconstruction",
  "mesh": {"shape": "torus", "major_radius": 1.0, "minor_radius": 0.35, "major_segments": 12, "minor_segments": 6},
  "domain": {"margin": 0.1},
  "lattices": [{"type": "cc", "resolution": [6, 6, 6]}, {"type": "bcc", "resolution": [5, 5, 10], "margin": 0.2}],
  "sampler": {"backend": "cpu", "threads": 1, "precision": "float", "progress": false},
  "reconstructions": [{"lattice": "cc", "interpolator": "trilinear"}],
  "metrics": {"domain_probes": 20, "band_probes": 20, "band": 1.0, "seed": 1}
}
)";
    const std::string cache = at("cache"), out = at("out");
    std::streambuf* const cout = std::cout.rdbuf();
    std::ostringstream sink;
    std::cout.rdbuf(sink.rdbuf());  // the plans
    const auto [parsed, refused] =
        fuzz(at("c.json"), seed, kPerSeed, 5000, [&](const std::string& path, const std::string& bytes) {
            test::write_file(path, bytes);
            RunnerOptions o;
            o.experiments = &experiment_registry();
            o.config_path = path;
            o.dry_run = true;
            o.no_cache = true;
            o.cache_dir = cache;
            o.output_root = out;
            run_experiment(o);
        });
    std::cout.rdbuf(cout);
    std::cout << "c.json: " << kPerSeed << " mutations, " << parsed << " parsed, " << refused << " refused\n";
    EXPECT_GT(parsed, 0);
    EXPECT_GT(refused, 0);
    EXPECT_FALSE(fs::exists(out));
}


TEST(FuzzSearch, CertifiedFloatSearchOnAdversarialCases) {
    for (const AdversarialCase& c : adversarial_cases(0x5eed22, 400)) {
        const PreparedMesh mesh = prepare_mesh(c.mesh);
        SamplerOptions o;
        o.backend = "cpu";
        o.method = "brute_force";
        o.precision = Precision::Double;
        o.progress = false;
        const std::vector<PointSample> want = make_sampler(o)->bind(share(mesh))->query(c.points);
        o.precision = Precision::Float;
        for (const char* method : {"brute_force", "bvh"}) {
            o.method = method;
            const std::vector<PointSample> got = make_sampler(o)->bind(share(mesh))->query(c.points);
            for (size_t i = 0; i < got.size(); ++i)
                ASSERT_TRUE(got[i].triangle == want[i].triangle && got[i].distance == want[i].distance &&
                            std::signbit(got[i].distance) == std::signbit(want[i].distance))
                    << c.mesh.name << " " << method << " point " << i;
        }
    }
}

}  // namespace
}  // namespace sdf
