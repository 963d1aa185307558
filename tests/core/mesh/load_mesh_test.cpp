// load_mesh_file(): every format and encoding written by independent writers
// (mesh_file_writers.h), plain and gzip-compressed, reads back as the same mesh as its OBJ
// through load_obj() (vertices and triangles identical; STL compared triangle by triangle
// after its exact welding) and gives bit-identical distances through the CPU brute force.
// Malformed files of each format get errors that name the file and the place.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/mesh/load_mesh.h"
#include "core/mesh/load_obj.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "tests/core/mesh/mesh_file_writers.h"
#include "tests/test_util/scratch_dir.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

using test::PlyEncoding;

/// A torus under an affine map with non-dyadic factors, so coordinates use all 53 bits.
TriangleMesh test_shape(bool float_coordinates) {
    TriangleMesh m = make_torus(1.0, 0.35, 24, 12);
    for (Vec3d& p : m.vertices) {
        p = {p.x * 0.731 + 0.1, p.y * 1.13 - 0.2, p.z * 0.917 + 1.0 / 3.0};
        if (float_coordinates) p = Vec3d(Vec3<float>(p));
    }
    return m;
}

struct FormatCase {
    const char* name;
    const char* extension;
    bool float_coordinates;  ///< the format stores float (binary STL, float PLY)
    bool welds;              ///< the format repeats corners (STL)
    std::string (*write)(const TriangleMesh&);
};

const FormatCase kFormats[] = {
    {"ply_ascii", "ply", false, false, [](const TriangleMesh& m) { return test::ply_text(m, PlyEncoding::Ascii); }},
    {"ply_binary_le", "ply", false, false, [](const TriangleMesh& m) { return test::ply_text(m, PlyEncoding::BinaryLittleEndian); }},
    {"ply_binary_be", "ply", false, false, [](const TriangleMesh& m) { return test::ply_text(m, PlyEncoding::BinaryBigEndian); }},
    {"ply_binary_be_float", "ply", true, false, [](const TriangleMesh& m) { return test::ply_text(m, PlyEncoding::BinaryBigEndian, true); }},
    {"stl_ascii", "stl", false, true, test::stl_ascii_text},
    {"stl_binary", "stl", true, true, test::stl_binary_text},
    {"off", "off", false, false, test::off_text},
    {"obj", "obj", false, false, test::obj_text},
};

class MeshFormats : public ::testing::TestWithParam<std::tuple<FormatCase, bool>> {};

std::vector<PointSample> distances(const TriangleMesh& mesh) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-2.0, 2.0);
    std::vector<Vec3d> points(300);
    for (Vec3d& p : points) p = {u(rng), u(rng), u(rng)};
    SamplerOptions o;
    o.precision = Precision::Double;
    o.progress = false;
    o.threads = 1;
    return make_cpu_brute_force_sampler(o)->bind(share(prepare_mesh(mesh)))->query(points);
}

TEST_P(MeshFormats, ReadBackEqualsTheObjAndGivesIdenticalDistances) {
    const auto& [format, gzip] = GetParam();
    test::ScratchDir dir("sdf_load_mesh_test");
    const TriangleMesh shape = test_shape(format.float_coordinates);
    const TriangleMesh reference = load_obj(dir.write("reference.obj", test::obj_text(shape)));

    const std::string file = dir.at(std::string("shape.") + format.extension + (gzip ? ".gz" : ""));
    if (gzip) test::write_gzip(file, format.write(shape));
    else dir.write(std::string("shape.") + format.extension, format.write(shape));
    const TriangleMesh read = load_mesh_file(file);

    EXPECT_EQ(read.name, "shape");
    EXPECT_EQ(read.source, file);
    EXPECT_EQ(read.content_sha256.size(), 64u);
    ASSERT_EQ(read.vertices.size(), reference.vertices.size());
    ASSERT_EQ(read.triangles.size(), reference.triangles.size());
    if (format.welds) {
        for (size_t i = 0; i < read.triangles.size(); ++i)
            for (int k = 0; k < 3; ++k)
                ASSERT_EQ(read.vertices[size_t(read.triangles[i][k])], reference.vertices[size_t(reference.triangles[i][k])])
                    << "triangle " << i << " corner " << k;
    } else {
        EXPECT_EQ(read.vertices, reference.vertices);
        EXPECT_EQ(read.triangles, reference.triangles);
    }

    const std::vector<PointSample> want = distances(reference), got = distances(read);
    for (size_t i = 0; i < want.size(); ++i) {
        ASSERT_EQ(got[i].distance, want[i].distance) << "point " << i;
        ASSERT_EQ(got[i].triangle, want[i].triangle) << "point " << i;
    }
}

INSTANTIATE_TEST_SUITE_P(AllFormats, MeshFormats, ::testing::Combine(::testing::ValuesIn(kFormats), ::testing::Bool()),
                         [](const auto& info) {
                             return std::string(std::get<0>(info.param).name) + (std::get<1>(info.param) ? "_gz" : "");
                         });

// ---- Content decides over the extension; unknown formats are named ---------------------

class LoadMeshErrors : public test::ScratchDirTest {
protected:
    LoadMeshErrors() : ScratchDirTest("sdf_load_mesh_errors") {}

    /// The message load_mesh_file throws for `text` written as `name`; checks it names the file and `expected`.
    void expect_error(const std::string& name, const std::string& text, const std::string& expected) {
        const std::string path = write(name, text);
        try {
            load_mesh_file(path);
            ADD_FAILURE() << name << ": no error; expected one containing \"" << expected << "\"";
        } catch (const std::runtime_error& e) {
            const std::string message = e.what();
            EXPECT_NE(message.find(path), std::string::npos) << message;
            EXPECT_NE(message.find(expected), std::string::npos) << "expected \"" << expected << "\" in: " << message;
        }
    }
};

const char* kTrianglePly =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

TEST_F(LoadMeshErrors, PlyNamedObjIsReadAsPly) {
    const TriangleMesh m = load_mesh_file(write("actually-ply.obj", kTrianglePly));
    ASSERT_EQ(m.triangles.size(), 1u);
    EXPECT_EQ(m.vertices[1], (Vec3d{1, 0, 0}));
}

TEST_F(LoadMeshErrors, UnknownFormatsAreNamed) {
    expect_error("scene.fbx", "Kaydara FBX Binary  \0\x1a", "unsupported mesh format 'fbx'");
    expect_error("noext", "hello\n", "unsupported mesh format (no extension");
}

TEST_F(LoadMeshErrors, Ply) {
    expect_error("magic.ply", "plx\n", "first line");
    expect_error("format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", "PLY header line 2: unknown format 'binary_middle_endian'");
    expect_error("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\nend_header\n", "line 4: unknown property type 'flot'");
    expect_error("noend.ply", "ply\nformat ascii 1.0\nelement vertex 1\n", "without 'end_header'");
    expect_error("nox.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\nproperty float z\nelement face 0\n"
                            "property list uchar int vertex_indices\nend_header\n1 2\n", "lacks property x");
    expect_error("noface.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                               "end_header\n1 2 3\n", "no element 'face'");
    std::string bad_index = kTrianglePly;
    bad_index.replace(bad_index.size() - 2, 1, "3");
    expect_error("index.ply", bad_index, "element 'face' 0 (line 13): vertex index 3 out of range");
    std::string bad_number = kTrianglePly;
    bad_number.replace(bad_number.find("1 0 0"), 1, "x");
    expect_error("number.ply", bad_number, "element 'vertex' 1 (line 11): expected a number, found 'x'");
    std::string two_corners = kTrianglePly;
    two_corners.replace(two_corners.size() - 8, 8, "2 0 1\n");
    expect_error("two.ply", two_corners, "face has 2 vertices");
    // Binary with fewer bytes than the header declares: refused before allocation.
    std::string truncated = test::ply_text(test_shape(false), PlyEncoding::BinaryLittleEndian);
    truncated.resize(truncated.size() / 2);
    expect_error("truncated.ply", truncated, "file ends early (truncated?)");
    std::string huge = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty double x\n"
                       "property double y\nproperty double z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n";
    expect_error("huge.ply", huge, "need at least 96000000000 bytes");
}

TEST_F(LoadMeshErrors, Stl) {
    expect_error("short.stl", "abc", "too short for binary STL");
    std::string binary = test::stl_binary_text(test_shape(true));
    binary.resize(binary.size() - 10);
    binary.replace(0, 5, "xxxxx");  // no "solid": cannot be ASCII either
    expect_error("truncated.stl", binary, "binary STL header: declares 576 triangles");
    expect_error("keyword.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertx 1 0 0\n", "ASCII STL line 5: expected 'vertex' or 'endloop', found 'vertx'");
    expect_error("nan.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\n", "line 5: non-finite vertex coordinate 'nan'");
    expect_error("open.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n", "file ends inside facet 0");
    expect_error("empty.stl", "solid s\nendsolid s\n", "no triangles");
}

const char* kTriangleFacet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";

/// Every byte of `message` printable (no raw binary data, no NUL cutting it short).
bool printable(const std::string& message) {
    for (const char c : message)
        if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) return false;
    return true;
}

TEST_F(LoadMeshErrors, StlPromises) {
    // A file cut after a complete facet is not complete.
    expect_error("cut.stl", std::string("solid s\n") + kTriangleFacet, "ASCII STL line 8: file ends after 1 facets without 'endsolid'");
    // A binary STL whose header begins with "solid" and whose size is wrong: named as binary, bytes escaped.
    std::string binary = test::stl_binary_text(test_shape(true));
    binary.resize(binary.size() - 10);
    const std::string path = write("solid-binary.stl", binary);
    try {
        load_mesh_file(path);
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("binary STL header: declares 576 triangles"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("begins with 'solid'"), std::string::npos) << e.what();
        EXPECT_TRUE(printable(e.what())) << e.what();
    }
    expect_error("normal.stl", "solid s\nfacet normal 0 x 1\n", "line 2: expected a facet normal component");
    expect_error("garbage.stl", std::string("solid s\n") + kTriangleFacet + "\x80\x81" "endsolid\n", "found '\\x80\\x81endsolid'");
}

TEST_F(LoadMeshErrors, StlKeywordsInAnyCaseOnAnyLinesAndNanNormals) {
    const std::vector<std::pair<std::string, std::string>> files = {
        {"upper.stl", "SOLID PART\nFACET NORMAL 0 0 1\nOUTER LOOP\nVERTEX 0 0 0\nVERTEX 1 0 0\nVERTEX 0 1 0\nENDLOOP\nENDFACET\nENDSOLID PART\n"},
        {"one-line.stl", "solid my part facet normal 0 0 1 outer loop vertex 0 0 0 vertex 1 0 0 vertex 0 1 0 endloop endfacet endsolid my part"},
        {"nan-normal.stl", "solid s\nfacet normal nan nan nan\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n"},
        {"mixed.stl", "Solid s\nFacet Normal -inf 0 0\nOuter Loop\nVertex 0 0 0\nVertex 1 0 0\nVertex 0 1 0\nEndLoop\nEndFacet\nEndSolid\n"}};
    for (const auto& [name, text] : files) {
        const TriangleMesh m = load_mesh_file(write(name, text));
        ASSERT_EQ(m.triangles.size(), 1u) << name;
        EXPECT_EQ(m.vertices[size_t(m.triangles[0].y)], (Vec3d{1, 0, 0})) << name;
    }
}

TEST_F(LoadMeshErrors, OffAndPlyCountsThatDoNotMatchTheData) {
    expect_error("extra.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n",
                 "OFF line 7: data continues after the 1 faces the header declares");
    std::string one_too_many = kTrianglePly;
    one_too_many.replace(one_too_many.find("vertex 3"), 8, "vertex 4");
    expect_error("vertices.ply", one_too_many,
                 "PLY element 'vertex' 3 (line 13): the line has more values than the element's properties (x y z)");
    std::string short_line = kTrianglePly;
    short_line.replace(short_line.find("1 0 0\n"), 6, "1 0\n");
    expect_error("short.ply", short_line, "PLY element 'vertex' 1 (line 11): the line ends after 2 values");
}

// Counts one too large and one too small, for vertices and faces, in every format that
// declares counts: each named with the line (or byte), the count and what was found (issue 26).
TEST_F(LoadMeshErrors, CountsOneTooLargeOrTooSmallAreNamedPrecisely) {
    const std::string off_body = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n";
    expect_error("v+1.off", "OFF\n5 2 0\n" + off_body,
                 "OFF line 7: expected 5 vertex lines, found 4 before the faces: this line ('3 0 1 2') is a face line, read "
                 "as vertex 4, and the file then ends after 1 of 2 faces (is the vertex count too large by 1?)");
    expect_error("v-1.off", "OFF\n3 2 0\n" + off_body,
                 "OFF line 6: expected face 0 of 2, found a vertex line ('0 0 1'): the header declares 3 vertices, but "
                 "vertex lines continue after them (is the vertex count too small?)");
    expect_error("f+1.off", "OFF\n4 3 0\n" + off_body,
                 "OFF line 8: file ends after 2 of 3 faces (expected 3 face lines, found 2; is the face count too large, "
                 "or the file truncated?)");
    expect_error("f-1.off", "OFF\n4 1 0\n" + off_body,
                 "OFF line 8: data continues after the 1 faces the header declares (found '3'; is the face count too small?)");
    // A bad face that is no vertex line keeps its own message.
    expect_error("bad-face.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n2 0 1\n3 0 1 3\n",
                 "OFF line 7: face 0 has vertex count '2'; expected 3 or more");

    const auto ply = [](const std::string& from, const std::string& to) {
        std::string text = kTrianglePly;
        text.replace(text.find(from), from.size(), to);
        return text;
    };
    expect_error("v+1.ply", ply("vertex 3", "vertex 4"),
                 "PLY element 'vertex' 3 (line 13): the line has more values than the element's properties (x y z)");
    expect_error("v-1.ply", ply("vertex 3", "vertex 2"),
                 "PLY element 'face' 0 (line 12): expected face 0 of 1, found a vertex line ('0 1 0'): the header declares 2 "
                 "vertices, but vertex lines continue after them (is the header's count of 'vertex' elements too small?)");
    expect_error("f+1.ply", ply("face 1", "face 2"),
                 "file ends after 1 of 2 'face' elements (expected 2 lines of them, found 1; is the header's count too "
                 "large, or the file truncated?)");
    expect_error("f-1.ply", ply("face 1", "face 0"), "PLY data (line 13 ('3')): data continues after the last declared element (is a count in the header too small?)");

    // Binary STL: the size tells both ways.
    std::string stl = test::stl_binary_text(test_shape(true));
    stl.replace(0, 5, "xxxxx");
    const uint32_t n = 576;
    for (const uint32_t wrong : {n + 1, n - 1}) {
        std::string text = stl;
        std::memcpy(text.data() + 80, &wrong, 4);
        expect_error("count" + std::to_string(wrong) + ".stl", text,
                     "binary STL header: declares " + std::to_string(wrong) + " triangles, which take " +
                         std::to_string(84 + 50 * wrong) + " bytes, but the file has " + std::to_string(stl.size()) +
                         (wrong > n ? " (truncated, or not STL)" : " (data after the declared triangles: is the count too small?"));
    }
}

TEST_F(LoadMeshErrors, Utf16WithoutByteOrderMarkIsNamed) {
    std::string utf16;
    for (const char c : std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")) { utf16 += c; utf16 += '\0'; }
    expect_error("wide.obj", utf16, "looks like UTF-16LE text without a byte-order mark");
    expect_error("wide.off", std::string("\0O\0F\0F\0\n", 8), "looks like UTF-16BE text without a byte-order mark");
}

TEST_F(LoadMeshErrors, NulBytesInTextAreNamedByByteAndLine) {
    const char obj[] = "v 0 0 0\nv 1 0 0\nv 0 1\0 0\nf 1 2 3\n";
    expect_error("nul.obj", std::string(obj, sizeof obj - 1), "line 3: byte 21 is a NUL byte");
    const char ply[] = "ply\nformat ascii 1.0\ncomment \0\nend_header\n";
    expect_error("nul.ply", std::string(ply, sizeof ply - 1), "PLY header line 3: byte 29 is a NUL byte");
}

// Classic Mac OS line ends (a lone CR) read like LF, in every text format and a binary PLY's header.
TEST_F(LoadMeshErrors, CarriageReturnLineEnds) {
    const TriangleMesh shape = test_shape(false);
    const auto cr = [](std::string s, size_t end = std::string::npos) {
        for (size_t i = 0; i < std::min(end, s.size()); ++i)
            if (s[i] == '\n') s[i] = '\r';
        return s;
    };
    const std::string binary_ply = test::ply_text(shape, PlyEncoding::BinaryLittleEndian);
    const std::vector<std::pair<std::string, std::string>> files = {
        {"cr.obj", cr(test::obj_text(shape))}, {"cr.off", cr(test::off_text(shape))},
        {"cr.ply", cr(test::ply_text(shape, PlyEncoding::Ascii))}, {"crb.ply", cr(binary_ply, binary_ply.find("end_header") + 11)},
        {"cr.stl", cr(test::stl_ascii_text(shape))}};
    const TriangleMesh reference = load_obj(write("reference.obj", test::obj_text(shape)));
    for (const auto& [name, text] : files) {
        const TriangleMesh m = load_mesh_file(write(name, text));
        ASSERT_EQ(m.triangles.size(), reference.triangles.size()) << name;
        for (size_t i = 0; i < m.triangles.size(); ++i)
            for (int k = 0; k < 3; ++k)
                ASSERT_EQ(m.vertices[size_t(m.triangles[i][k])], reference.vertices[size_t(reference.triangles[i][k])]) << name;
    }
    expect_error("cr-error.off", "OFF\r3 1 0\r0 0 0\r1 0\r0 1 0\r3 0 1 2\r", "OFF line 4: vertex line has fewer than 3 coordinates");
}

TEST_F(LoadMeshErrors, Off) {
    expect_error("header.off", "OF\n", "expected 'OFF'");
    expect_error("dim.off", "4OFF\n1 1 0\n", "4-D and n-D OFF");
    expect_error("binary.off", "OFF BINARY\n", "binary OFF is not supported");
    expect_error("counts.off", "OFF\n1000 1000 0\n0 0 0\n", "more than the file's remaining");
    expect_error("coords.off", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "OFF line 4: vertex line has fewer than 3 coordinates");
    expect_error("index.off", "OFF\n# comment\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n", "OFF line 7: face 0 refers to vertex 5");
    expect_error("short.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "file ends after 1 of 2 faces");
}

TEST_F(LoadMeshErrors, OffAcceptsColoursCommentsAndCountsOnTheKeywordLine) {
    const TriangleMesh m = load_mesh_file(write("c.off", "COFF 4 2 0 # counts here\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n"
                                                        "1 1 0 0 0 255 255\n0 1 0 1 1 1 255\n4 0 1 2 3 0.5 0.5 0.5\n3 0 2 3\n"));
    ASSERT_EQ(m.triangles.size(), 3u);  // the quad as a fan, then the triangle
    EXPECT_EQ(m.triangles[1], (Int3{0, 2, 3}));
    EXPECT_EQ(m.vertices[2], (Vec3d{1, 1, 0}));
}

/// `zeros` zero bytes gzip-compressed into `path`, written a megabyte at a time.
void write_gzip_zeros(const std::string& path, size_t zeros, const std::string& prefix = "") {
    gzFile f = gzopen(path.c_str(), "wb1");
    gzwrite(f, prefix.data(), unsigned(prefix.size()));
    const std::string chunk(size_t(1) << 20, '\0');
    for (size_t done = 0; done < zeros; done += chunk.size()) gzwrite(f, chunk.data(), unsigned(std::min(chunk.size(), zeros - done)));
    gzclose(f);
}

long peak_rss_kib() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_maxrss;
}

// A gzip bomb is refused from its first decompressed megabyte, whatever its size: here 256
// MiB of zeros (1 MB compressed) as OBJ (text: a NUL byte), as STL (binary: more than its
// header declares) and as a binary STL followed by zeros. Peak memory grows by a few MiB.
TEST_F(LoadMeshErrors, GzipIsDecompressedOnlyAsFarAsTheContentAllows) {
    const size_t zeros = size_t(256) << 20;
    write_gzip_zeros(at("zeros.obj.gz"), zeros);
    write_gzip_zeros(at("zeros.stl.gz"), zeros);
    write_gzip_zeros(at("tail.stl.gz"), zeros, test::stl_binary_text(test_shape(true)));
    const long before = peak_rss_kib();
    expect_error("zeros.obj.gz", test::read_text(at("zeros.obj.gz")), "line 1: byte 0 is a NUL byte");
    expect_error("zeros.stl.gz", test::read_text(at("zeros.stl.gz")), "decompresses to more than 84 bytes (what its binary STL header declares: 0 triangles, 84 + 50 x 0 bytes)");
    expect_error("tail.stl.gz", test::read_text(at("tail.stl.gz")), "decompresses to more than 28884 bytes");
    EXPECT_LT(peak_rss_kib() - before, 64 * 1024) << "KiB";
}

// A binary PLY's header declares its size (elements x their properties' sizes, lists at
// their count type's largest count, nothing after the last element): a .ply.gz is
// decompressed no further, whatever follows in the stream (issue 26). Here a triangle
// followed by 256 MiB of zeros (1 MB compressed).
TEST_F(LoadMeshErrors, BinaryPlyGzipIsDecompressedNoFurtherThanItsHeaderDeclares) {
    const std::string header =
        "ply\nformat binary_little_endian 1.0\ncomment bounded\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    std::string data = header;
    for (const float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) data.append(reinterpret_cast<const char*>(&v), 4);
    data += char(3);
    for (const int32_t i : {0, 1, 2}) data.append(reinterpret_cast<const char*>(&i), 4);
    test::write_gzip(at("triangle.ply.gz"), data);
    EXPECT_EQ(load_mesh_file(at("triangle.ply.gz")).triangles.size(), 1u);

    write_gzip_zeros(at("bomb.ply.gz"), size_t(256) << 20, data);
    const long before = peak_rss_kib();
    const uint64_t most = header.size() + 3 * 12 + 1 * (1 + 255 * 4);
    expect_error("bomb.ply.gz", test::read_text(at("bomb.ply.gz")),
                 "decompresses to more than " + std::to_string(most) + " bytes (what its binary PLY header declares: " +
                     std::to_string(header.size()) + " header bytes, element 'vertex' 3 x 12 bytes, element 'face' 1 x at "
                     "most 1021 bytes)");
    EXPECT_LT(peak_rss_kib() - before, 64 * 1024) << "KiB";
    // Within the bound, what follows the last element is the reader's to refuse.
    write_gzip_zeros(at("tail.ply.gz"), 16, data);
    expect_error("tail.ply.gz", test::read_text(at("tail.ply.gz")), "data continues after the last declared element");
    // A byte-order mark and CRLF line ends before big-endian doubles.
    const std::string big = "\xEF\xBB\xBFply\r\nformat binary_big_endian 1.0\r\nelement vertex 1\r\nproperty double x\r\n"
                            "property double y\r\nproperty double z\r\nend_header\r\n";
    write_gzip_zeros(at("big.ply.gz"), size_t(16) << 20, big);
    expect_error("big.ply.gz", test::read_text(at("big.ply.gz")),
                 "decompresses to more than " + std::to_string(big.size() + 24) + " bytes (what its binary PLY header declares: " +
                     std::to_string(big.size() - 3) + " header bytes, element 'vertex' 1 x 24 bytes)");
}

TEST_F(LoadMeshErrors, GzipMembersConcatenatedAndDataAfterTheStream) {
    test::write_gzip(at("a.gz"), std::string(kTrianglePly).substr(0, 40));
    test::write_gzip(at("b.gz"), std::string(kTrianglePly).substr(40));
    const std::string two = test::read_text(at("a.gz")) + test::read_text(at("b.gz"));
    EXPECT_EQ(load_mesh_file(write("two-members.ply.gz", two)).triangles.size(), 1u);
    expect_error("trailing.ply.gz", two + "junk", "data after the end of the gzip stream (byte " + std::to_string(two.size()));
}

TEST_F(LoadMeshErrors, Gzip) {
    std::string gz;
    {
        const std::string path = at("whole.ply.gz");
        test::write_gzip(path, kTrianglePly);
        gz = test::read_text(path);
    }
    expect_error("cut.ply.gz", gz.substr(0, gz.size() - 12), "gzip stream");
    std::string corrupt = gz;
    for (size_t i = 12; i < corrupt.size() - 8; ++i) corrupt[i] = char(corrupt[i] ^ 0x5a);
    expect_error("corrupt.ply.gz", corrupt, "gzip stream");
}

}  // namespace
}  // namespace sdf
