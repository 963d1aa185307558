// The .npy reader and writer (harness/io/npy_file.h): round trips of every dtype and shape
// (NumPy reading our files and we reading NumPy's are checked by tests/python_module), and
// every refusal naming the file and what was expected.
#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "harness/io/npy_file.h"
#include "harness/io/points_file.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

using test::Contains;

class NpyFile : public test::ScratchDirTest {
protected:
    NpyFile() : ScratchDirTest("sdf_npy_file_test") {}

    /// A version 1.0 file with `header` as its dictionary and `data` after it.
    static std::string with_header(const std::string& header, const std::string& data, int major = 1) {
        std::string h = header + "\n";
        std::string out = "\x93NUMPY";
        out += char(major);
        out += char(0);
        out += char(h.size() & 0xFF);
        out += char(h.size() >> 8);
        if (major > 1) out += std::string(2, '\0');
        return out + h + data;
    }

    /// The message of parsing `bytes` as file "bad.npy" ("" when it parses).
    static std::string refusal(const std::string& bytes) {
        try {
            parse_npy(bytes, "bad.npy");
        } catch (const std::runtime_error& e) {
            return e.what();
        }
        return "";
    }
};

TEST_F(NpyFile, EveryDtypeAndShapeRoundTrips) {
    const std::vector<double> d = {1.5, -2.25, 1e-300, std::numeric_limits<double>::max(), -0.0, 3};
    write_npy(at("d.npy"), d, {2, 3});
    const NpyArray a = read_npy(at("d.npy"));
    EXPECT_EQ(a.dtype, NpyDtype::Float64);
    EXPECT_EQ(a.shape, (std::vector<int64_t>{2, 3}));
    EXPECT_EQ(a.shape_text(), "(2, 3)");
    ASSERT_EQ(a.data.size(), d.size() * 8);
    EXPECT_EQ(std::memcmp(a.data.data(), d.data(), a.data.size()), 0);

    const std::vector<float> f = {0.5f, -1.0f, 7.0f};
    write_npy(at("f.npy"), NpyDtype::Float32, {3}, f.data());
    EXPECT_EQ(read_npy(at("f.npy")).to_doubles(), (std::vector<double>{0.5, -1.0, 7.0}));
    EXPECT_EQ(read_npy(at("f.npy")).shape_text(), "(3,)");

    const std::vector<int32_t> i = {-7, 0, 2147483647, 4};
    write_npy(at("i.npy"), NpyDtype::Int32, {2, 1, 2}, i.data());
    EXPECT_EQ(read_npy(at("i.npy")).to_doubles(), (std::vector<double>{-7, 0, 2147483647, 4}));

    const std::vector<int64_t> l = {int64_t(1) << 40};
    write_npy(at("l.npy"), NpyDtype::Int64, {}, l.data());  // 0-d
    const NpyArray scalar = read_npy(at("l.npy"));
    EXPECT_EQ(scalar.count(), 1);
    EXPECT_EQ(scalar.to_doubles()[0], double(int64_t(1) << 40));

    write_npy(at("empty.npy"), NpyDtype::Float64, {0, 3}, nullptr);
    EXPECT_EQ(read_npy(at("empty.npy")).count(), 0);
    try {  // an array without points is no points file (harness/io/points_file.h)
        read_points_file(at("empty.npy"));
        FAIL() << "read an empty points file";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()),
                  at("empty.npy") + ": no points: the array has shape (0, 3); expected (N, 3) with N >= 1");
    }
}

TEST_F(NpyFile, HeadersAreAlignedAndNeverOverwritten) {
    const std::string bytes = npy_bytes(NpyDtype::Float64, {5, 3}, std::vector<double>(15, 1.0).data());
    const size_t header_end = bytes.size() - 15 * 8;
    EXPECT_EQ(header_end % 64, 0u);
    EXPECT_EQ(bytes[header_end - 1], '\n');
    write_npy(at("x.npy"), std::vector<double>{1}, {1});
    try {
        write_npy(at("x.npy"), std::vector<double>{2}, {1});
        FAIL() << "overwrote x.npy";
    } catch (const std::runtime_error& e) {
        EXPECT_TRUE(Contains(e.what(), "x.npy")) << e.what();
    }
    write_npy(at("x.npy"), std::vector<double>{2}, {1}, Overwrite::Allow);
    EXPECT_EQ(read_npy(at("x.npy")).to_doubles()[0], 2.0);
}

TEST_F(NpyFile, PointsFilesAreReadByExtension) {
    const std::vector<double> p = {0, 1, 2, 3.5, -4, 5e-3};
    write_npy(at("p.NPY"), p, {2, 3});
    const std::vector<Vec3d> points = read_points_file(at("p.NPY"));
    ASSERT_EQ(points.size(), 2u);
    EXPECT_EQ(points[1].x, 3.5);
    EXPECT_EQ(points[1].z, 5e-3);
    write_npy(at("wrong.npy"), p, {3, 2});
    try {
        read_points_file(at("wrong.npy"));
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_TRUE(Contains(e.what(), "wrong.npy: expected an array of shape (N, 3)")) << e.what();
        EXPECT_TRUE(Contains(e.what(), "got shape (3, 2)")) << e.what();
    }
    const std::vector<double> nan = {0, 0, 0, 1, std::numeric_limits<double>::quiet_NaN(), 0};
    write_npy(at("nan.npy"), nan, {2, 3});
    try {
        read_points_file(at("nan.npy"));
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_TRUE(Contains(e.what(), "nan.npy: row 1 is not three finite numbers")) << e.what();
    }
}

TEST_F(NpyFile, BadFilesAreRefusedByName) {
    const std::string eight(8, '\0');
    const std::string ok = "{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }";
    EXPECT_EQ(refusal(with_header(ok, eight)), "");
    EXPECT_EQ(refusal(with_header("{\"shape\": (1,), \"descr\": \"<f8\", \"fortran_order\": False}", eight, 2)), "");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"PK\x03\x04 not npy at all", "not a NumPy .npy file"},
        {with_header(ok, eight, 4), "version 4.0 is not supported"},
        {with_header("{'descr': '>f8', 'fortran_order': False, 'shape': (1,), }", eight), "'>f8' (big-endian)"},
        {with_header("{'descr': '|O', 'fortran_order': False, 'shape': (1,), }", eight), "(Python objects)"},
        {with_header("{'descr': '<c16', 'fortran_order': False, 'shape': (1,), }", eight), "expected one of '<f4', '<f8', '<i4', '<i8'"},
        {with_header("{'descr': '<f8', 'fortran_order': True, 'shape': (1,), }", eight), "Fortran order is not supported"},
        {with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), 'x': 1}", eight), "unexpected or repeated key 'x'"},
        {with_header("{'descr': '<f8', 'descr': '<f8', 'shape': (1,), }", eight), "unexpected or repeated key 'descr'"},
        {with_header("{'descr': '<f8', 'shape': (1,), }", eight), "expected the keys"},
        {with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (1), }", eight), "written (N,)"},
        {with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (-1,), }", eight), "non-negative integers"},
        {with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 4294967296), }", eight),
         "does not fit 64 bits"},
        {with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999999999999,), }", eight),
         "does not fit 64 bits"},
        {with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }", eight), "needs 48 bytes of data; the file has 8"},
        {with_header(ok, eight + "x"), "needs 8 bytes of data; the file has 9"},
        {with_header(ok, eight, 2).substr(0, 11), "truncated .npy header"},
        {with_header(ok, eight).substr(0, 20), "the .npy header claims"},
        {with_header(ok + " extra", eight), "text after the header's closing '}'"},
        {with_header("{'descr': '<f8, 'fortran_order': False}", eight), "bad.npy: header:"},
    };
    for (const auto& [bytes, expected] : cases) {
        const std::string message = refusal(bytes);
        EXPECT_TRUE(Contains(message, "bad.npy")) << expected << ": " << message;
        EXPECT_TRUE(Contains(message, expected)) << "expected \"" << expected << "\", got: " << message;
    }
}

TEST_F(NpyFile, NonRegularFilesAreNamed) {
    try {
        read_npy(at("."));
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_TRUE(Contains(e.what(), "directory")) << e.what();
    }
}

}  // namespace
}  // namespace sdf
