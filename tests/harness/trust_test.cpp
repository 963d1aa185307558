// Issue 11, "trustworthy on every input": each class of bad input the tools once crashed on
// or answered wrongly with exit code 0, run through every tool it reaches, with the clear
// error (naming the file, line or key) or the correct answer asserted. Correct answers are
// against closed-form truth: the unit-corner tetrahedron's distances and a linear field that
// trilinear reconstruction reproduces exactly.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <regex>
#include <string>
#include <vector>

#include "core/checked_math.h"
#include "core/io/text_file.h"
#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/prepared_mesh.h"
#include "harness/config/json_reader.h"
#include "harness/io/field_file.h"
#include "harness/io/points_file.h"
#include "harness/provenance/version.h"
#include "harness_test_util.h"

#if !defined(SDF_QUERY_EXE) || !defined(SDF_EVAL_EXE) || !defined(SDF_RENDER_EXE) || !defined(RUN_EXPERIMENT_EXE) || \
    !defined(SDF_SAMPLE_EXE)
#error "the tools' paths must be defined by CMake"
#endif

namespace sdf {
namespace {

namespace fs = std::filesystem;
using test::Contains;
using test::error_of;
using test::quote;
using test::ShellResult;

const std::string kBom = "\xEF\xBB\xBF";

/// The tetrahedron with corners 0, e_x, e_y, e_z, outward, in OBJ; `eol` ends each line.
std::string tetra_obj(const std::string& eol = "\n") {
    return "v 0 0 0" + eol + "v 1 0 0" + eol + "v 0 1 0" + eol + "v 0 0 1" + eol + "f 1 3 2" + eol + "f 1 2 4" + eol +
           "f 1 4 3" + eol + "f 2 3 4" + eol;
}
std::string tetra_ply(const std::string& eol) {
    return "ply" + eol + "format ascii 1.0" + eol + "element vertex 4" + eol + "property float x" + eol +
           "property float y" + eol + "property float z" + eol + "element face 4" + eol +
           "property list uchar int vertex_indices" + eol + "end_header" + eol + "0 0 0" + eol + "1 0 0" + eol +
           "0 1 0" + eol + "0 0 1" + eol + "3 0 2 1" + eol + "3 0 1 3" + eol + "3 0 3 2" + eol + "3 1 2 3" + eol;
}
std::string tetra_off(const std::string& eol) {
    return "OFF" + eol + "4 4 0" + eol + "0 0 0" + eol + "1 0 0" + eol + "0 1 0" + eol + "0 0 1" + eol + "3 0 2 1" +
           eol + "3 0 1 3" + eol + "3 0 3 2" + eol + "3 1 2 3" + eol;
}
std::string tetra_stl(const std::string& eol) {
    const char* faces[4][3] = {{"0 0 0", "0 1 0", "1 0 0"},
                               {"0 0 0", "1 0 0", "0 0 1"},
                               {"0 0 0", "0 0 1", "0 1 0"},
                               {"1 0 0", "0 1 0", "0 0 1"}};
    std::string s = "solid tetra" + eol;
    for (const auto& f : faces) {
        s += "facet normal 0 0 0" + eol + " outer loop" + eol;
        for (const char* v : f) s += "  vertex " + std::string(v) + eol;
        s += " endloop" + eol + "endfacet" + eol;
    }
    return s + "endsolid tetra" + eol;
}

/// Points with known distances to the tetrahedron: inside (nearest: the three axis faces at
/// 0.2; the slanted face is (1 - 0.6)/sqrt(3) away), and outside (nearest: the corner e_x).
const std::string kPointsText = "0.2 0.2 0.2\n3 0 0\n";
const double kTruth[2] = {-0.2, 2.0};

/// Distances of sdf-query's output lines.
std::vector<double> distances(const std::string& out) {
    std::vector<double> d;
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ls(line);
        double v = NAN;
        ls >> v;
        d.push_back(v);
    }
    return d;
}

class Trust : public test::ScratchDirTest {
protected:
    Trust() : ScratchDirTest("sdf_trust_test") {}

    ShellResult run(const std::string& exe, const std::string& args) const {
        return test::run_in(dir_, "SDF_DATA_PATH=" + quote(at("nowhere")) + " SDF_CACHE_DIR=" + quote(at("cache")) +
                                      " " + quote(exe) + " " + args);
    }
    ShellResult query(const std::string& args) const { return run(SDF_QUERY_EXE, args); }
    ShellResult eval(const std::string& args) const { return run(SDF_EVAL_EXE, args); }
    ShellResult render(const std::string& args) const { return run(SDF_RENDER_EXE, args); }
    ShellResult experiment(const std::string& args) const { return run(RUN_EXPERIMENT_EXE, args); }
    ShellResult sample(const std::string& args) const { return run(SDF_SAMPLE_EXE, args); }

    /// A tiny config sampling `mesh` (a file name or "shape:box").
    std::string config(const std::string& rel, const std::string& mesh, const std::string& resolution = "[4, 4, 4]",
                       const std::string& prefix = "", const std::string& eol = "\n") const {
        const std::string mesh_json = mesh.rfind("shape:", 0) == 0 ? "{\"shape\": \"" + mesh.substr(6) + "\"}"
                                                                     : "{\"file\": \"" + mesh + "\"}";
        return write(rel, prefix + "{" + eol + "  \"name\": \"trust\"," + eol + "  \"mesh\": " + mesh_json + "," + eol +
                              "  \"lattices\": [{\"type\": \"cc\", \"resolution\": " + resolution + "}]," + eol +
                              "  \"sampler\": {\"threads\": 1, \"progress\": false}" + eol + "}" + eol);
    }

    /// A CC 2x2x2 field of f = x + y + z (spacing 1, origin 0), whose header starts with
    /// `prefix` and ends lines with `eol`; f is symmetric in the axes, so the point order of
    /// the channel does not matter.
    std::string linear_field(const std::string& rel, const std::string& prefix = "", const std::string& eol = "\n",
                             const std::string& resolution = "[2, 2, 2]", const std::string& extra = "") const {
        std::string raw;
        for (int i = 0; i < 8; ++i) {
            const float f = float((i & 1) + ((i >> 1) & 1) + ((i >> 2) & 1));
            raw.append(reinterpret_cast<const char*>(&f), sizeof f);
        }
        write("f.value.raw", raw);
        return write(rel, prefix + "{" + eol + "\"format\": \"sdf-lattice-field\", \"version\": 1," + eol + extra +
                              "\"lattice\": {\"type\": \"cc\", \"origin\": [0, 0, 0], \"spacing\": 1, \"resolution\": " +
                              resolution + "}," + eol +
                              "\"channels\": {\"value\": {\"file\": \"f.value.raw\", \"dtype\": \"float32\"}}" + eol +
                              "}" + eol);
    }
};

// ---- 1. degenerate meshes -------------------------------------------------------------------

const std::string kDegenerateObj = "v 0 0 0\nv 1 1 1\nv 2 2 2\nv 0 1 0\nf 1 2 3\nf 1 1 4\nf 4 4 4\n";

TEST(TrustDegenerate, PrepareMeshRefusesAMeshWithNoTriangleLeft) {
    TriangleMesh m;
    m.name = "flat";
    m.source = "flat.obj";
    m.vertices = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {0, 1, 0}};
    m.triangles = {{0, 1, 2}, {0, 0, 3}};  // collinear, repeated index
    const std::string e = error_of([&] { prepare_mesh(m); });
    EXPECT_TRUE(Contains(e, "flat.obj: no triangle left"));
    EXPECT_TRUE(Contains(e, "all 2 triangles are degenerate"));
    // One good triangle left: prepared, with the other two counted as dropped.
    m.triangles.push_back({0, 3, 1});
    EXPECT_EQ(prepare_mesh(m).triangles().size(), 1u);
    EXPECT_EQ(prepare_mesh(m).report().degenerate_triangles, 2);
}

TEST_F(Trust, EveryToolRefusesAnAllDegenerateMeshNamingIt) {
    write("flat.obj", kDegenerateObj);
    write("p.txt", kPointsText);
    const ShellResult q = query("flat.obj p.txt");  // was SIGSEGV
    EXPECT_EQ(q.code, 1) << q.err;
    EXPECT_TRUE(Contains(q.err, "flat.obj: no triangle left"));
    const ShellResult r = render("flat.obj --no-cache --quiet --size 8 --backend cpu --sampler-backend cpu");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_TRUE(Contains(r.err, "flat.obj: no triangle left"));
    const ShellResult e = experiment(config("c.json", "flat.obj") + " --dry-run --no-cache");
    EXPECT_EQ(e.code, 1) << e.err;
    EXPECT_TRUE(Contains(e.err, "flat.obj: no triangle left"));
}

// ---- 2. text encodings: byte-order marks and CRLF ------------------------------------------

TEST_F(Trust, EveryTextMeshFormatReadsBomAndCrlfToTheSameDistances) {
    write("p.txt", kPointsText);
    const std::vector<std::pair<std::string, std::string>> meshes = {
        {"t.obj", tetra_obj("\r\n")}, {"t.ply", tetra_ply("\r\n")}, {"t.off", tetra_off("\r\n")},
        {"t.stl", tetra_stl("\r\n")}};
    for (const auto& [name, text] : meshes) {
        for (const std::string& prefix : {std::string(), kBom}) {
            write(name, prefix + text);
            const ShellResult r = query(name + " p.txt --precision double");
            ASSERT_EQ(r.code, 0) << name << (prefix.empty() ? "" : " with BOM") << ": " << r.err;
            const std::vector<double> d = distances(r.out);
            ASSERT_EQ(d.size(), 2u) << name;
            EXPECT_NEAR(d[0], kTruth[0], 1e-15) << name << (prefix.empty() ? "" : " with BOM");
            EXPECT_NEAR(d[1], kTruth[1], 1e-15) << name << (prefix.empty() ? "" : " with BOM");
        }
    }
}

TEST_F(Trust, BomBeforeTheFirstObjVertexKeepsEveryIndex) {
    // Before: the BOM glued to "v" hid vertex 1; every face index shifted by one.
    write("t.obj", kBom + tetra_obj());
    const TriangleMesh m = load_mesh_file(at("t.obj"));
    ASSERT_EQ(m.vertices.size(), 4u);
    EXPECT_EQ(m.vertices[1].x, 1.0);
    ASSERT_EQ(m.triangles.size(), 4u);
    EXPECT_EQ(m.triangles[0][0], 0);
    EXPECT_EQ(m.triangles[0][1], 2);
}

TEST_F(Trust, PointsConfigsAndFieldHeadersReadBomAndCrlf) {
    write("t.obj", tetra_obj());
    write("p.txt", kBom + "# points\r\n0.2 0.2 0.2\r\n\r\n3 0 0\r\n");
    const ShellResult q = query("t.obj p.txt --precision double");
    ASSERT_EQ(q.code, 0) << q.err;
    const std::vector<double> d = distances(q.out);
    ASSERT_EQ(d.size(), 2u);
    EXPECT_NEAR(d[0], kTruth[0], 1e-15);
    EXPECT_NEAR(d[1], kTruth[1], 1e-15);

    const ShellResult e = experiment(config("c.json", "shape:box", "[4, 4, 4]", kBom, "\r\n") + " --dry-run");
    EXPECT_EQ(e.code, 0) << e.err;

    write("q.txt", kBom + "0.5 0.5 0.25\r\n");
    const ShellResult f = eval(linear_field("field.json", kBom, "\r\n") + " q.txt --interpolator trilinear");
    ASSERT_EQ(f.code, 0) << f.err;
    EXPECT_NEAR(distances(f.out).at(0), 1.25, 1e-6);  // trilinear is exact for x + y + z
}

TEST_F(Trust, WideEncodingsAreRefusedByName) {
    const std::string utf16 = std::string("\xFF\xFE", 2) + std::string("v\0 \0", 4);
    write("w.obj", utf16);
    write("w.txt", utf16);
    write("w.json", utf16);
    write("p.txt", kPointsText);
    const ShellResult m = query("w.obj p.txt");
    EXPECT_EQ(m.code, 1);
    EXPECT_TRUE(Contains(m.err, "w.obj: mesh file is encoded as UTF-16LE"));
    const ShellResult p = query("shape:box w.txt");
    EXPECT_EQ(p.code, 1);
    EXPECT_TRUE(Contains(p.err, "w.txt: points file is encoded as UTF-16LE"));
    const ShellResult c = experiment("w.json --dry-run");
    EXPECT_EQ(c.code, 1);
    EXPECT_TRUE(Contains(c.err, "w.json: config file is encoded as UTF-16LE"));
}

// ---- 3. integer overflow ----------------------------------------------------------------------

TEST(TrustOverflow, CheckedArithmetic) {
    EXPECT_EQ(checked_mul(int64_t(1) << 31, int64_t(1) << 31).value(), int64_t(1) << 62);
    EXPECT_FALSE(checked_mul(int64_t(1) << 32, int64_t(1) << 31).has_value());
    EXPECT_FALSE(checked_add(INT64_MAX, 1).has_value());
    EXPECT_EQ(checked_mul(2000, 3000, 4000).value(), int64_t(24000000000));
    EXPECT_FALSE(checked_mul(2000000000, 2000000000, 2000000000).has_value());
    // BCC: primary + secondary grid; the largest lattice is accepted, one point more is not.
    EXPECT_EQ(checked_lattice_points(LatticeType::BCC, {3, 4, 5}), 60 + 2 * 3 * 4);
    EXPECT_EQ(checked_lattice_points(LatticeType::CC, {4096, 4096, 4096}), kMaxLatticePoints);
    EXPECT_TRUE(Contains(error_of([] { checked_lattice_points(LatticeType::CC, {4096, 4096, 4097}); }),
                         "has 68736253952 points, more than the largest lattice sampled"));
    EXPECT_TRUE(Contains(
        error_of([] { checked_lattice_points(LatticeType::BCC, {2000000000, 2000000000, 1000000000}); }),
        "2000000000x2000000000x2000000000 has more than 2^63 points"));
}

TEST_F(Trust, FaceIndicesBeyond32BitsAreRefusedNotWrapped) {
    // 4294967297 = 2^32 + 1 wrapped to vertex 1 before.
    write("big.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 4294967297 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    write("p.txt", kPointsText);
    const ShellResult r = query("big.obj p.txt");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(Contains(r.err, "big.obj:5: face vertex '4294967297' refers to vertex 4294967297, but the file has 4"));
    write("huge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999999\n");
    const ShellResult h = query("huge.obj p.txt");
    EXPECT_EQ(h.code, 1);
    EXPECT_TRUE(Contains(h.err, "huge.obj:4: face vertex '99999999999999999999999' is not a whole number"));
}

TEST_F(Trust, OverflowingLatticeIsRefusedBeforeAnythingIsPlannedOrCached) {
    // Before: --dry-run printed "0 points" and the run crashed, leaving a cache entry.
    const std::string c = config("c.json", "shape:box", "[2000000000, 2000000000, 2000000000]");
    for (const std::string flags : {" --dry-run", ""}) {
        const ShellResult r = experiment(c + flags);
        EXPECT_EQ(r.code, 1) << flags;
        EXPECT_TRUE(Contains(r.err, "c.json: key 'lattices[0].resolution'")) << flags;
        EXPECT_TRUE(Contains(r.err, "more than 2^63 points")) << flags;
    }
    EXPECT_FALSE(fs::exists(at("cache")) && !fs::is_empty(at("cache")));
    EXPECT_FALSE(fs::exists(at("results")));
    const ShellResult big = experiment(config("d.json", "shape:box", "[5000, 5000, 5000]") + " --dry-run");
    EXPECT_EQ(big.code, 1);
    EXPECT_TRUE(Contains(big.err, "has 125000000000 points, more than the largest lattice sampled"));
}

// ---- 2. far points and extreme scales ------------------------------------------------------

/// The tetrahedron scaled by 2^k, written with 17 digits so that its coordinates round-trip.
std::string scaled_tetra_obj(int k) {
    char v[64];
    std::snprintf(v, sizeof v, "%.17g", std::ldexp(1.0, k));
    const std::string s = v;
    return "v 0 0 0\nv " + s + " 0 0\nv 0 " + s + " 0\nv 0 0 " + s + "\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
}

TEST_F(Trust, FarPointsGetTheOutsideSignAndDistancesToTheirPrecision) {
    // Before: 3e7 unit-sphere sizes away the float search picked a triangle on the far side
    // and printed a negative distance; at 1e20 the vectorised float kernel crashed.
    write("far.txt", "3e7 0 0\n0 -3e8 1\n2e9 2e9 -2e9\n1e15 0 0\n");
    const ShellResult f = query("shape:sphere far.txt");
    const ShellResult d = query("shape:sphere far.txt --precision double");
    ASSERT_EQ(f.code, 0) << f.err;
    ASSERT_EQ(d.code, 0) << d.err;
    const std::vector<double> df = distances(f.out), dd = distances(d.out);
    ASSERT_EQ(df.size(), 4u);
    ASSERT_EQ(dd.size(), 4u);
    for (size_t i = 0; i < 4; ++i) {
        EXPECT_GT(df[i], 0) << i;
        EXPECT_GT(dd[i], 0) << i;
        // The float search may tie triangles whose squared distances round alike: the error
        // stays within two units of float's relative rounding.
        EXPECT_LE(std::abs(df[i] - dd[i]), dd[i] * std::ldexp(1.0, -23)) << i;
    }
    EXPECT_NEAR(dd[0], 3e7 - 1, 1e-6 * 3e7);
    // Beyond the float search's range: refused, naming the point; double answers.
    write("farther.txt", "0 0 0\n1e20 0 0\n");
    const ShellResult refused = query("shape:sphere farther.txt");
    EXPECT_EQ(refused.code, 1);
    EXPECT_TRUE(Contains(refused.err, "query points: row 1 has a coordinate of magnitude 1e+20, beyond the float search's "
                                      "range of 1.15e+18"))
        << refused.err;
    EXPECT_TRUE(Contains(refused.err, "use precision double"));
    const ShellResult far_double = query("shape:sphere farther.txt --precision double");
    ASSERT_EQ(far_double.code, 0) << far_double.err;
    EXPECT_EQ(distances(far_double.out).at(1), 1e20);
    EXPECT_EQ(query("shape:sphere far.txt").out, f.out);  // identical runs, identical bits
}

TEST_F(Trust, TinyAndHugeMeshesAreExactInDoubleAndRefusedInFloat) {
    // Power-of-two scales are exact in binary floating point, so the double distances of the
    // scaled tetrahedron are the unit one's times 2^k, bit for bit.
    write("unit.obj", scaled_tetra_obj(0));
    write("p.txt", kPointsText);
    const std::vector<double> unit = distances(query("unit.obj p.txt --precision double").out);
    ASSERT_EQ(unit.size(), 2u);
    for (int k : {-70, -66, 66, 120}) {
        const std::string name = "t" + std::to_string(k) + ".obj";
        write(name, scaled_tetra_obj(k));
        char points[128];
        std::snprintf(points, sizeof points, "%.17g %.17g %.17g\n%.17g 0 0\n", std::ldexp(0.2, k), std::ldexp(0.2, k),
                      std::ldexp(0.2, k), std::ldexp(3.0, k));
        write("p" + std::to_string(k) + ".txt", points);
        const ShellResult d = query(name + " p" + std::to_string(k) + ".txt --precision double");
        ASSERT_EQ(d.code, 0) << k << d.err;
        const std::vector<double> got = distances(d.out);
        ASSERT_EQ(got.size(), 2u);
        EXPECT_EQ(got[0], std::ldexp(unit[0], k)) << k;
        EXPECT_EQ(got[1], std::ldexp(unit[1], k)) << k;
        // Float: 2^-70 and 2^-66 across are below 2^-40 (squared distances would underflow),
        // 2^66 and 2^120 beyond 2^60 (they would overflow). Before: distances off by 1-2x.
        const ShellResult f = query(name + " p" + std::to_string(k) + ".txt");
        EXPECT_EQ(f.code, 1) << k << f.out;
        EXPECT_TRUE(Contains(f.err, "mesh '")) << f.err;
        EXPECT_TRUE(Contains(f.err, name)) << f.err;
        EXPECT_TRUE(Contains(f.err, k < 0 ? "below the float search's smallest extent" : "beyond the float search's range"))
            << f.err;
    }
    // A lattice study of a mesh out of float range is refused before anything is sampled.
    const ShellResult r = experiment(config("c.json", "t-70.obj") + " --output-root out --quiet");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(Contains(r.err, "below the float search's smallest extent")) << r.err;
    EXPECT_FALSE(fs::exists(at("out/trust")) && !fs::is_empty(at("out/trust")));
    EXPECT_FALSE(fs::exists(at("cache/fields")) && !fs::is_empty(at("cache/fields")));
}

// ---- 5. memory: estimated in the plan, refused up front -----------------------------------

TEST_F(Trust, RunThatDoesNotFitInMemoryIsRefusedBeforeSampling) {
    // Before: std::bad_alloc (or the OOM killer) after sampling had started; --dry-run said
    // nothing. 1000^3 points need about 60 GiB; the machine is told it has 1 GiB.
    const std::string c = config("m.json", "shape:box", "[1000, 1000, 1000]");
    const std::string one_gib = "SDF_MEMORY_AVAILABLE=1073741824 ";
    const ShellResult plan = run(RUN_EXPERIMENT_EXE, c + " --dry-run");  // the real figure: a plan line
    EXPECT_EQ(plan.code, 0) << plan.err;
    EXPECT_TRUE(Contains(plan.out, "memory: about 60.1 GiB of host memory for sampling cc 1000x1000x1000 "
                                   "(1,000,000,000 points)"))
        << plan.out;
    const ShellResult dry = test::run_in(dir_, one_gib + "SDF_CACHE_DIR=" + quote(at("cache")) + " " +
                                                   quote(RUN_EXPERIMENT_EXE) + " " + c + " --dry-run");
    EXPECT_EQ(dry.code, 0);
    EXPECT_TRUE(Contains(dry.out, "1 GiB available (the run would be refused)")) << dry.out;
    const ShellResult r = test::run_in(dir_, one_gib + "SDF_CACHE_DIR=" + quote(at("cache")) + " " +
                                                 quote(RUN_EXPERIMENT_EXE) + " " + c);
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(Contains(r.err, "m.json: sampling cc 1000x1000x1000 (1,000,000,000 points) needs about 60.1 GiB of "
                                "host memory, and 1 GiB is available; nothing was computed"))
        << r.err;
    EXPECT_FALSE(fs::exists(at("results")));
    EXPECT_FALSE(fs::exists(at("cache")) && !fs::is_empty(at("cache")));
    // A small run passes the same check.
    const ShellResult small = test::run_in(dir_, one_gib + "SDF_CACHE_DIR=" + quote(at("cache")) + " " +
                                                     quote(RUN_EXPERIMENT_EXE) + " " + config("s.json", "shape:box") +
                                                     " --quiet");
    EXPECT_EQ(small.code, 0) << small.err;
}

// Issue 26: a mesh whose declared sizes are legal but larger than the memory this process
// may use (ulimit -v) ends with exit code 1 and a message naming the file and the size, not
// a bare std::bad_alloc: while decompressing it, and while building the mesh from it.
TEST_F(Trust, MeshLargerThanTheMemoryLimitIsNamedWithItsSize) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: ulimit -v cannot be used";
#endif
    // 60 million float vertices at the origin (720 MB, 0.7 MB gzip-compressed) and one triangle.
    const uint64_t vertices = 60000000;
    const std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(vertices) +
                               "\nproperty float x\nproperty float y\nproperty float z\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n";
    const uint64_t bytes = header.size() + vertices * 12 + 13;
    {
        gzFile f = gzopen(at("big.ply.gz").c_str(), "wb1");
        ASSERT_TRUE(f != nullptr);
        gzwrite(f, header.data(), unsigned(header.size()));
        const std::string zeros(size_t(1) << 20, '\0');
        for (uint64_t done = 0; done < vertices * 12; done += zeros.size())
            gzwrite(f, zeros.data(), unsigned(std::min<uint64_t>(zeros.size(), vertices * 12 - done)));
        const char face[13] = {3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0};
        gzwrite(f, face, sizeof face);
        ASSERT_EQ(gzclose(f), Z_OK);
    }
    write("p.txt", "0 0 0\n");
    const auto limited = [&](int kib) {
        return test::run_in(dir_, "ulimit -v " + std::to_string(kib) + " && " + quote(SDF_QUERY_EXE) + " big.ply.gz p.txt");
    };
    // 500 MB: the decompressed content does not fit.
    const ShellResult decompress = limited(500000);
    EXPECT_EQ(decompress.code, 1) << decompress.err;
    EXPECT_TRUE(Contains(decompress.err, "big.ply.gz: not enough memory to decompress the mesh file: ")) << decompress.err;
    EXPECT_TRUE(Contains(decompress.err, std::to_string(bytes) + " bytes decompressed (a buffer of that size could not be allocated)"))
        << decompress.err;
    // 1.5 GB: the content fits, its 60 million vertices in double (1.44 GB) do not.
    const ShellResult build = limited(1500000);
    EXPECT_EQ(build.code, 1) << build.err;
    EXPECT_TRUE(Contains(build.err, "big.ply.gz: not enough memory to read the PLY mesh (" + std::to_string(bytes) +
                                    " bytes decompressed)"))
        << build.err;
    for (const ShellResult* r : {&decompress, &build}) {
        EXPECT_FALSE(Contains(r->err, "std::bad_alloc")) << r->err;
        EXPECT_TRUE(r->out.empty()) << r->out;
    }
}

// Issue 26: a points file's bad line is quoted with its control and non-ASCII bytes escaped
// (a NUL no longer cuts the message short, raw bytes no longer reach the terminal).
TEST_F(Trust, PointsFileErrorsQuoteTheLineWithItsBytesEscaped) {
    const std::string nul = write("nul.txt", std::string("0 0 0\n1 2 3\0\n", 13));
    EXPECT_EQ(error_of([&] { read_points_file(nul); }),
              nul + ":2: expected three finite numbers \"x y z\", got '1 2 3\\x00'");
    const std::string binary = write("binary.txt", "0 0 0\n\x80\x81 1 1\n");
    EXPECT_EQ(error_of([&] { read_points_file(binary); }),
              binary + ":2: expected three finite numbers \"x y z\", got '\\x80\\x81 1 1'");
    const ShellResult r = query(quote(write("t.obj", tetra_obj())) + " " + quote(nul));
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(Contains(r.err, "got '1 2 3\\x00'")) << r.err;
}

// Both tools that read points files refuse one without points (harness/io/points_file.h),
// as sdf-query does in every format (cli_test.cpp): sdf-eval printed nothing and exited 0.
TEST_F(Trust, SdfEvalRefusesAPointsFileWithoutPoints) {
    const std::string field = linear_field("f.json");
    write("none.txt", "# no points\n");
    const ShellResult r = eval(field + " none.txt --interpolator trilinear");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(Contains(r.err, "sdf-eval: error: none.txt: no points: expected \"x y z\" per line")) << r.err;
    EXPECT_EQ(r.out, "");
}

TEST_F(Trust, RenderLargerThanMemoryIsRefusedWithTheFigure) {
    const ShellResult huge = render("shape:sphere --size 100000 --out x.pfm");
    EXPECT_EQ(huge.code, 2);  // beyond 16384, the configs' limit too
    EXPECT_TRUE(Contains(huge.err, "--size: Value 100000 not in range 1 to 16384"));
    const ShellResult grid = test::run_in(dir_, "SDF_MEMORY_AVAILABLE=1073741824 " + quote(SDF_RENDER_EXE) +
                                                    " shape:sphere --grid --size 8192 --out-dir g");
    EXPECT_EQ(grid.code, 1);
    EXPECT_TRUE(Contains(grid.err, "a grid of 8192x8192 pixel panels needs about 102 GiB of host memory, and 1 GiB is "
                                   "available; nothing was computed"))
        << grid.err;
    EXPECT_FALSE(fs::exists(at("g")));
}

TEST_F(Trust, FieldHeaderWithAnOverflowingResolutionIsRefused) {
    write("p.txt", "0 0 0\n");
    const ShellResult r =
        eval(linear_field("h.json", "", "\n", "[2000000000, 2000000000, 2000000000]") + " p.txt --interpolator trilinear");
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(Contains(r.err, "h.json: key 'lattice.resolution'"));
    EXPECT_TRUE(Contains(r.err, "more than 2^63 points"));
}

// ---- 4. files that are not regular files -----------------------------------------------------

TEST_F(Trust, DirectoriesAndArraysAreNamedForWhatTheyAre) {
    fs::create_directories(at("adir.json"));
    fs::create_directories(at("pdir"));
    write("p.txt", kPointsText);
    write("t.obj", tetra_obj());
    const ShellResult q = query("t.obj pdir");  // was: no output, exit 0
    EXPECT_EQ(q.code, 1);
    EXPECT_TRUE(Contains(q.err, "pdir: cannot read points file: it is a directory, not a regular file"));
    const ShellResult e = eval(linear_field("f.json") + " pdir --interpolator trilinear");
    EXPECT_EQ(e.code, 1);
    EXPECT_TRUE(Contains(e.err, "pdir: cannot read points file: it is a directory"));
    const ShellResult h = eval("adir.json p.txt --interpolator trilinear");
    EXPECT_EQ(h.code, 1);
    EXPECT_TRUE(Contains(h.err, "adir.json: cannot read field header: it is a directory, not a regular file"));
    const ShellResult c = experiment("adir.json --dry-run");
    EXPECT_EQ(c.code, 1);
    EXPECT_TRUE(Contains(c.err, "adir.json: cannot read config file: it is a directory, not a regular file"));
    write("array.json", "[1, 2, 3]\n");
    const ShellResult a = eval("array.json p.txt --interpolator trilinear");
    EXPECT_EQ(a.code, 1);
    EXPECT_TRUE(Contains(a.err, "array.json: the top level: expected a JSON object, got an array [1,2,3]"));
    const ShellResult m = query(at("pdir") + " p.txt");
    EXPECT_EQ(m.code, 1);
    EXPECT_TRUE(Contains(m.err, "pdir: cannot read mesh file: it is a directory, not a regular file"));
    const ShellResult rel = query("pdir p.txt");
    EXPECT_EQ(rel.code, 1);
    EXPECT_TRUE(Contains(rel.err, "pdir (a directory, not a regular file)"));
}

// ---- 5. smaller ones ---------------------------------------------------------------------------

TEST_F(Trust, ObjIndexErrorsQuoteTheIndexAsWritten) {
    write("p.txt", kPointsText);
    write("neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -7 -2 -1\n");  // was quoted as "vertex -3"
    const ShellResult n = query("neg.obj p.txt");
    EXPECT_EQ(n.code, 1);
    EXPECT_TRUE(Contains(n.err, "neg.obj:4: face vertex '-7' counts back further than the 3 vertices before this line"));
    write("frac.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1.5 2 3\n");  // was read as f 1 2 3
    const ShellResult f = query("frac.obj p.txt");
    EXPECT_EQ(f.code, 1);
    EXPECT_TRUE(Contains(f.err, "frac.obj:4: face vertex '1.5' is not a whole number"));
    write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    const ShellResult z = query("zero.obj p.txt");
    EXPECT_EQ(z.code, 1);
    EXPECT_TRUE(Contains(z.err, "zero.obj:4: face vertex '0' is 0"));
    // Relative indices, texture and normal references are still read.
    write("rel.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\nf -4/1/1 -2/1/1 -3/1/1\nf 1//1 2//1 4//1\n"
                     "f 1 4 3\nf 2 3 4\n");
    const ShellResult ok = query("rel.obj p.txt --precision double");
    ASSERT_EQ(ok.code, 0) << ok.err;
    EXPECT_NEAR(distances(ok.out).at(0), kTruth[0], 1e-15);
    EXPECT_NEAR(distances(ok.out).at(1), kTruth[1], 1e-15);
}

TEST_F(Trust, DuplicateKeysAndHugeNumbersInJsonAreErrors) {
    write("dup.json", "{\"name\": \"a\", \"mesh\": {\"shape\": \"box\", \"shape\": \"sphere\"}, \"lattices\": []}");
    const ShellResult d = experiment("dup.json --dry-run");
    EXPECT_EQ(d.code, 1);
    EXPECT_TRUE(Contains(d.err, "dup.json: key 'shape' appears twice in one object"));
    // The same key in two different objects is fine.
    EXPECT_NO_THROW(read_json_file(write("two.json", "{\"a\": {\"x\": 1}, \"b\": {\"x\": 2}, \"x\": [{\"x\": 3}]}")));
    write("p.txt", "0 0 0\n");
    const ShellResult h = eval(linear_field("h.json", "", "\n", "[2, 2, 2]", "\"version\": 1,") + " p.txt --interpolator trilinear");
    EXPECT_EQ(h.code, 1);
    EXPECT_TRUE(Contains(h.err, "h.json: key 'version' appears twice"));
    write("big.json", "{\"name\": \"a\", \"x\": 1e400}");
    const ShellResult b = experiment("big.json --dry-run");  // was a raw nlohmann exception
    EXPECT_EQ(b.code, 1);
    EXPECT_TRUE(Contains(b.err, "big.json: number overflow parsing '1e400'"));
}

TEST_F(Trust, CommandLineErrorsExitWithCode2InEveryTool) {
    write("p.txt", "0 0 0\n");
    const std::string field = linear_field("f.json");
    const std::vector<std::pair<std::string, std::string>> bad = {
        {SDF_QUERY_EXE, "shape:box p.txt --threads -1"},
        {SDF_QUERY_EXE, "shape:box"},
        {SDF_QUERY_EXE, "shape:box p.txt --no-such-option"},
        {SDF_QUERY_EXE, "shape:box p.txt --method octree"},
        {SDF_QUERY_EXE, "shape:box p.txt --backend gpu"},
        {SDF_EVAL_EXE, field + " p.txt --interpolator trilinear --threads -1"},
        {SDF_EVAL_EXE, field + " p.txt"},
        {SDF_RENDER_EXE, "shape:box --fov 0"},
        {SDF_RENDER_EXE, "shape:box --fov 180"},
        {SDF_RENDER_EXE, "shape:box --margin -1"},
        {SDF_RENDER_EXE, "shape:box --threads -2"},
        {SDF_RENDER_EXE, "shape:box --size 0"},
        {SDF_RENDER_EXE, "shape:box --grid --panels bcc_cubic,bcc_quintic"},       // no such filter
        {SDF_RENDER_EXE, "shape:box --grid --panels bcc_box_quintic/true"},        // reads no derivatives
        {RUN_EXPERIMENT_EXE, "--no-such-option"},
        {RUN_EXPERIMENT_EXE, ""},
    };
    for (const auto& [exe, args] : bad) {
        const ShellResult r = run(exe, args);
        EXPECT_EQ(r.code, 2) << exe << " " << args << ": " << r.err;
        EXPECT_FALSE(r.err.empty()) << exe << " " << args;
    }
    for (const std::string exe : {SDF_QUERY_EXE, SDF_EVAL_EXE, SDF_RENDER_EXE, RUN_EXPERIMENT_EXE})
        EXPECT_EQ(run(exe, "--help").code, 0) << exe;
}

TEST_F(Trust, EveryToolPrintsItsVersionAndCommit) {
    const std::vector<std::pair<std::string, std::string>> tools = {
        {SDF_QUERY_EXE, "sdf-query"}, {SDF_EVAL_EXE, "sdf-eval"}, {SDF_RENDER_EXE, "sdf-render"},
        {RUN_EXPERIMENT_EXE, "run-experiment"}};
    const std::regex line(R"(([a-z-]+) (\d+\.\d+\.\d+) \(commit ([0-9a-f]{40}|unknown)(, with uncommitted changes)?\)\n)");
    for (const auto& [exe, name] : tools) {
        const ShellResult r = run(exe, "--version");
        EXPECT_EQ(r.code, 0) << name << ": " << r.err;
        std::smatch m;
        ASSERT_TRUE(std::regex_match(r.out, m, line)) << name << ": " << r.out;
        EXPECT_EQ(m[1].str(), name);
        EXPECT_EQ(m[2].str(), project_version());
        EXPECT_EQ(m[3].str(), build_commit());
    }
}

TEST_F(Trust, RenderRefusesACameraWithoutADefinedRoll) {
    const std::string common = " --no-cache --quiet --size 8 --backend cpu --sampler-backend cpu --out x.png";
    const ShellResult zero = render("shape:box --eye 3,3,3 --target 0,0,0 --up 0,0,0" + common);
    EXPECT_EQ(zero.code, 1);
    EXPECT_TRUE(Contains(zero.err, "is zero or parallel to the line of sight"));
    const ShellResult parallel = render("shape:box --eye 3,3,3 --target 0,0,0 --up 1,1,1" + common);
    EXPECT_EQ(parallel.code, 1);
    EXPECT_TRUE(Contains(parallel.err, "is zero or parallel to the line of sight"));
    const ShellResult ignored = render("shape:box --view three_quarter --up 0,0,1" + common);
    EXPECT_EQ(ignored.code, 1);
    EXPECT_TRUE(Contains(ignored.err, "--up applies to an explicit camera only"));
    EXPECT_FALSE(fs::exists(at("x.png")));
}

TEST_F(Trust, RenderFlagsAreReadByTheConfigsRenderCodec) {
    // sdf-render's flags become a config's "render" object (harness/config/render_spec.h): a
    // panel given twice is refused as in a config, before anything is sampled.
    const ShellResult twice = render("shape:box --grid --no-cache --quiet --size 8 --backend cpu --sampler-backend cpu "
                                     "--panels catmull_rom,bcc_linear,catmull_rom/fd --out-dir grid");
    EXPECT_EQ(twice.code, 1);
    EXPECT_TRUE(Contains(twice.err, "the command line: key 'render.panels[2]': \"catmull_rom/fd\" is already panel A"))
        << twice.err;
    EXPECT_FALSE(Contains(twice.err, "sampling"));
    EXPECT_FALSE(fs::exists(at("grid")));
}

// ---- 6. results that claim success with nothing measured ---------------------------------------

TEST_F(Trust, ReconstructionStudyThatPlacesNoProbeFails) {
    // A band far wider than the common domain: every band probe lands outside it. Before:
    // all errors 0, exit 0.
    const std::string study = R"({"name": "noprobes", "kind": "reconstruction", "mesh": {"shape": "box"},
        "lattices": [{"type": "cc", "resolution": [6, 6, 6]}],
        "sampler": {"threads": 1, "progress": false},
        "reconstructions": [{"lattice": "cc", "interpolator": "trilinear"}],
        "metrics": {"domain_probes": 0, "band_probes": 50, "band": 1e6}})";
    write("noprobes.json", study);
    const ShellResult r = experiment("noprobes.json --no-cache --output-root out");
    EXPECT_EQ(r.code, 1) << r.out << r.err;
    EXPECT_TRUE(Contains(r.err, "noprobes.json: key 'metrics': no probe was placed"));
    EXPECT_FALSE(fs::exists(at("out/noprobes")) && !fs::is_empty(at("out/noprobes")));
    // The same study with probes in the domain runs.
    std::string fine = study;
    fine.replace(fine.find("\"domain_probes\": 0"), 18, "\"domain_probes\": 9");
    fine.replace(fine.find("\"band\": 1e6"), 11, "\"band\": 1");
    write("probes.json", fine);
    const ShellResult ok = experiment("probes.json --no-cache --output-root out");
    EXPECT_EQ(ok.code, 0) << ok.out << ok.err;
}

TEST_F(Trust, ImageMetadataNamesTheFinalRunNotItsStagingDirectory) {
    // Before: the images' provenance "run" was the hidden staging directory's path.
    write("pics.json", R"({"name": "pics", "kind": "reconstruction", "mesh": {"shape": "box"},
        "lattices": [{"type": "cc", "resolution": [6, 6, 6]}, {"type": "bcc", "resolution": [5, 5, 10]}],
        "sampler": {"threads": 1, "progress": false},
        "metrics": {"domain_probes": 20, "band_probes": 20, "band": 1},
        "render": {"size": [24, 24], "views": ["front"]}})");
    const ShellResult r = experiment("pics.json --no-cache --output-root out --quiet");
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    std::vector<fs::path> runs;
    for (const auto& e : fs::directory_iterator(at("out/pics"))) runs.push_back(e.path());
    ASSERT_EQ(runs.size(), 1u);  // the run, and no reservation or staging left behind
    const std::string id = runs[0].filename().string();
    int summaries = 0;
    for (const auto& e : fs::recursive_directory_iterator(runs[0])) {
        if (e.path().string().find("_summary.json") == std::string::npos) continue;
        ++summaries;
        const nlohmann::json summary = read_json_file(e.path().string());
        EXPECT_EQ(summary.at("provenance").at("run"), "pics/" + id) << e.path();
    }
    EXPECT_GE(summaries, 1);
}

// ---- Issue 38: refused before the work, each problem by its name ---------------------------

TEST_F(Trust, RunExperimentRefusesABandItsFieldFilesCannotStoreInThePlan) {
    // 1e-300 is no float32 (the default output dtype): it was sampled and cached first, then
    // refused when the field was written, on every rerun; and --dry-run said nothing.
    write("band.json", R"({"name": "band", "mesh": {"shape": "box"},
        "lattices": [{"type": "cc", "resolution": [4, 4, 4]}],
        "sampler": {"threads": 1, "progress": false, "band_width": 1e-300}})");
    for (const std::string dry : {" --dry-run", ""}) {
        const ShellResult r = experiment("band.json --output-root out" + dry);
        EXPECT_NE(r.code, 0) << dry;
        EXPECT_TRUE(Contains(r.err, "band_width: 1e-300 cannot be stored in float32")) << dry << ": " << r.err;
        EXPECT_FALSE(Contains(r.out, "sampling with")) << dry << ": " << r.out;
        EXPECT_FALSE(fs::exists(at("cache"))) << dry << ": a field was cached";
    }
    // The reconstruction study writes its fields (float32) too: the same refusal in its plan
    // (it sampled, cached and then failed); a band below double's normal range, which not even
    // the float64 cache can store, is refused by the sampler options in every kind.
    write("recon.json", R"({"name": "recon", "kind": "reconstruction", "mesh": {"shape": "box"},
        "lattices": [{"type": "cc", "resolution": [4, 4, 4]}],
        "reconstructions": [{"lattice": "cc", "interpolator": "trilinear"}],
        "sampler": {"threads": 1, "progress": false, "band_width": 1e-300}})");
    write("subnormal.json", R"({"name": "subnormal", "mesh": {"shape": "box"},
        "lattices": [{"type": "cc", "resolution": [4, 4, 4]}], "output": {"dtype": "float64"},
        "sampler": {"threads": 1, "progress": false, "band_width": 1e-310}})");
    for (const std::string dry : {" --dry-run", ""}) {
        const ShellResult r = experiment("recon.json --output-root out" + dry);
        EXPECT_NE(r.code, 0) << dry;
        EXPECT_TRUE(Contains(r.err, "band_width: 1e-300 cannot be stored in float32")) << dry << ": " << r.err;
        EXPECT_TRUE(Contains(r.err, "fields")) << dry << ": " << r.err;
        EXPECT_FALSE(Contains(r.out, "sampling with")) << dry << ": " << r.out;
        const ShellResult sub = experiment("subnormal.json --output-root out" + dry);
        EXPECT_NE(sub.code, 0) << dry;
        EXPECT_TRUE(Contains(sub.err, "band_width")) << dry << ": " << sub.err;
        EXPECT_TRUE(Contains(sub.err, "a normal double")) << dry << ": " << sub.err;
        EXPECT_FALSE(Contains(sub.out, "sampling with")) << dry << ": " << sub.out;
        EXPECT_FALSE(fs::exists(at("cache"))) << dry << ": a field was cached";
    }
}

TEST_F(Trust, RunExperimentRefusesACacheDirThatIsAFileInThePlan) {
    config("c.json", "shape:box");
    write("taken", "a regular file\n");
    for (const std::string dry : {" --dry-run", ""}) {
        const ShellResult r = experiment("c.json --output-root out --cache-dir taken" + dry);
        EXPECT_NE(r.code, 0) << dry;
        EXPECT_TRUE(Contains(r.err, "--cache-dir taken: is a regular file")) << dry << ": " << r.err;
        EXPECT_FALSE(Contains(r.out, "sampling with")) << dry << ": " << r.out;
        EXPECT_FALSE(fs::exists(at("out"))) << dry;
    }
    write("dir/file", "x");
    const ShellResult under = experiment("c.json --output-root out --cache-dir dir/file/cache --dry-run");
    EXPECT_NE(under.code, 0);
    EXPECT_TRUE(Contains(under.err, "is a regular file")) << under.err;
}

TEST_F(Trust, SdfSampleDryRunReportsTheBudgetTheRunRefuses) {
    // 50 MB available, a 1 GB budget for a 128^3 lattice: the run refuses it; so must the dry run.
    const std::string args = "shape:box --resolution 128 --memory-budget 1G --out f.json --quiet";
    const ShellResult dry = test::run_in(dir_, "SDF_MEMORY_AVAILABLE=50000000 " + quote(SDF_SAMPLE_EXE) + " " + args + " --dry-run");
    const ShellResult real = test::run_in(dir_, "SDF_MEMORY_AVAILABLE=50000000 " + quote(SDF_SAMPLE_EXE) + " " + args);
    EXPECT_NE(real.code, 0);
    EXPECT_TRUE(Contains(real.err, "exceeds the")) << real.err;
    EXPECT_NE(dry.code, 0) << dry.out;
    EXPECT_TRUE(Contains(dry.err, "the run would be refused")) << dry.err;
    EXPECT_TRUE(Contains(dry.err, "exceeds the")) << dry.err;
    EXPECT_FALSE(fs::exists(at("f.json")));
}

TEST_F(Trust, SdfRenderChecksItsOutputBeforeSampling) {
    const ShellResult r = render("shape:box --resolution 8,8,8 --size 16 --out nowhere/box.png --quiet");
    EXPECT_NE(r.code, 0);
    EXPECT_TRUE(Contains(r.err, "nowhere/box.png: the folder")) << r.err;
    EXPECT_FALSE(fs::exists(at("cache"))) << "a field was sampled (and cached) before the output was checked";
    write("taken.png", "x");
    const ShellResult exists = render("shape:box --resolution 8,8,8 --size 16 --out taken.png --quiet");
    EXPECT_NE(exists.code, 0);
    EXPECT_TRUE(Contains(exists.err, "taken.png: already exists")) << exists.err;
    EXPECT_FALSE(fs::exists(at("cache")));
}

TEST_F(Trust, SdfRenderNamesTheCameraProblem) {
    const std::string base = "shape:box --resolution 8,8,8 --size 16 --no-cache --quiet ";
    struct Case {
        std::string args, expected;
    };
    const std::vector<Case> cases = {
        {"--eye nan,0,0 --target 0,0,0 --out a.png", "--eye nan,0,0: expected three finite numbers"},
        {"--eye 1e308,1e308,1e308 --target -1e308,-1e308,-1e308 --out b.png", "are too far apart"},
        {"--fov 1e-12 --out c.png", "is too small for a 16x16 image"},
    };
    for (const Case& c : cases) {
        const ShellResult r = render(base + c.args);
        EXPECT_NE(r.code, 0) << c.args;
        EXPECT_TRUE(Contains(r.err, c.expected)) << c.args << ": " << r.err;
        EXPECT_FALSE(Contains(r.err, "parallel")) << c.args << ": " << r.err;
    }
}

TEST(TrustMessages, AFloat32RangeRefusalPrintsAReadableNumber) {
    SampledField f;
    f.lattice.type = LatticeType::CC;
    f.lattice.spacing = 1;
    f.lattice.resolution = {2, 1, 1};
    f.distance = {0.5, 1e300};
    f.gradient = {{1, 0, 0}, {1, 0, 0}};
    f.closest_triangle = {0, 0};
    const test::ScratchDir dir("sdf_trust_float32");
    FieldWriteOptions o;
    o.dtype = FieldDtype::Float32;
    try {
        write_field(dir.at("f.json"), f, o);
        ADD_FAILURE() << "1e300 was written as float32";
    } catch (const std::exception& e) {
        const std::string what = e.what();
        EXPECT_TRUE(Contains(what, "value 1e+300 of point 1 is beyond float32's range")) << what;
        EXPECT_LT(what.size(), 300u) << what;
    }
}

}  // namespace
}  // namespace sdf
