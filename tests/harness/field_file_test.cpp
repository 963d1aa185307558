// Field files (JSON header + raw little-endian channels), NRRD and 8-bit exports, and the
// atomic file/directory primitives. Fields are synthetic with known values; headers written
// "by a user" are built by hand here, and exported headers are parsed independently.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "harness/config/json_reader.h"
#include "harness/io/atomic_file.h"
#include "harness/io/field_file.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::Contains;
using test::error_of;
using test::read_json;
using test::read_text;
using test::sorted_entries;

template <typename T>
void write_raw(const fs::path& p, const std::vector<T>& v) {
    std::ofstream out(p, std::ios::binary);
    out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(T)));
}

Lattice make_lattice(LatticeType type, Int3 res) {
    Lattice l;
    l.type = type;
    l.resolution = res;
    l.origin = {-1.0 / 3.0, 0.1, 2.0};  // not representable in float
    l.spacing = 0.1 + 1e-12;
    return l;
}

/// A field with values that float32 cannot hold exactly.
SampledField make_field(LatticeType type, Int3 res, bool gradient = true) {
    SampledField f;
    f.lattice = make_lattice(type, res);
    const int64_t n = f.lattice.num_points();
    f.resize(n);
    for (int64_t i = 0; i < n; ++i) {
        f.distance[size_t(i)] = std::sin(0.37 * double(i)) / 3.0 - 0.01 * double(i % 7);
        const double a = 0.11 * double(i), b = 0.07 * double(i);
        f.gradient[size_t(i)] = {std::cos(a) * std::sin(b), std::sin(a) * std::sin(b), std::cos(b)};
        f.closest_triangle[size_t(i)] = int32_t((i * 7919) % 100003);
    }
    if (!gradient) f.gradient.clear();
    f.precision = Precision::Double;
    f.sampler.backend = "cpu";
    f.sampler.method = "brute_force";
    f.sampler.kernel = "vectorized";
    f.sampler.precision = "double";
    f.sampler.points_computed = n;
    f.sampler.details["threads"] = 1;
    f.sampler.band = BandReport{0.5, n - 3, 3, "post-processed"};
    f.mesh.name = "synthetic";
    return f;
}

class FieldFiles : public test::ScratchDirTest {
protected:
    FieldFiles() : ScratchDirTest("sdf_field_file_test") {}
};

// ---- round trips ------------------------------------------------------------------------

// Writers that fill the channel files by parts (the MPI-IO write of harness/distributed) use
// field_channel_files and field_channel_bytes: the bytes of any cut of the points, placed at
// first * bytes_per_point, must be write_field's file, byte for byte.
TEST_F(FieldFiles, ChannelBytesOfPartsAreTheWrittenFiles) {
    for (const LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        for (const FieldDtype dtype : {FieldDtype::Float32, FieldDtype::Float64}) {
            const SampledField f = make_field(type, {5, 4, 3});
            FieldWriteOptions o;
            o.dtype = dtype;
            const std::string header = at(std::string(type == LatticeType::CC ? "cc" : "bcc") +
                                          (dtype == FieldDtype::Float32 ? "32" : "64") + ".json");
            write_field(header, f, o);
            const std::vector<FieldChannelFile> files = field_channel_files(header, f, o);
            ASSERT_EQ(files.size(), 3u);
            const json channels = read_json(header)["channels"];
            const size_t n = size_t(f.size());
            for (const FieldChannelFile& c : files) {
                SCOPED_TRACE(c.path);
                EXPECT_EQ(fs::path(c.path).filename().string(), channels.at(c.name).at("file").get<std::string>());
                const std::string on_disk = read_text(c.path);
                ASSERT_EQ(on_disk.size(), n * c.bytes_per_point());
                std::string parts;
                for (const auto& [first, count] : {std::pair<size_t, size_t>{0, 7}, {7, n - 20}, {n - 13, 13}}) {
                    const std::vector<char> bytes = field_channel_bytes(f, c, first, count);
                    ASSERT_EQ(bytes.size(), count * c.bytes_per_point());
                    parts.append(bytes.data(), bytes.size());
                }
                EXPECT_TRUE(parts == on_disk);
            }
        }
    }
}

TEST_F(FieldFiles, RoundTripFloat64IsExact) {
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        const SampledField f = make_field(type, {4, 5, 3});
        const std::string header = at(type == LatticeType::CC ? "cc.json" : "bcc.json");
        FieldWriteOptions o;
        o.dtype = FieldDtype::Float64;
        write_field(header, f, o);
        const SampledField g = read_field(header);
        EXPECT_EQ(g.lattice.type, type);
        EXPECT_EQ(g.lattice.resolution, f.lattice.resolution);
        EXPECT_EQ(g.lattice.origin, f.lattice.origin);  // JSON keeps doubles exactly
        EXPECT_EQ(g.lattice.spacing, f.lattice.spacing);
        ASSERT_EQ(g.size(), f.lattice.num_points());
        EXPECT_EQ(g.distance, f.distance);
        ASSERT_EQ(g.gradient.size(), f.gradient.size());
        for (size_t i = 0; i < f.gradient.size(); ++i) EXPECT_EQ(g.gradient[i], f.gradient[i]) << i;
        EXPECT_EQ(g.closest_triangle, f.closest_triangle);
        EXPECT_EQ(g.precision, Precision::Double);
        EXPECT_EQ(nlohmann::json(g.mesh), nlohmann::json(f.mesh));
        EXPECT_EQ(nlohmann::json(g.sampler), nlohmann::json(f.sampler));
    }
}

TEST_F(FieldFiles, RoundTripFloat32IsFloatRounding) {
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        const SampledField f = make_field(type, {3, 4, 6});
        const std::string header = at("f32.json");
        fs::remove_all(dir_);
        fs::create_directories(dir_);
        write_field(header, f);  // float32 is the default
        const SampledField g = read_field(header);
        ASSERT_EQ(g.size(), f.size());
        for (size_t i = 0; i < f.distance.size(); ++i) {
            EXPECT_EQ(g.distance[i], double(float(f.distance[i]))) << i;
            EXPECT_LE(std::abs(g.distance[i] - f.distance[i]), 0x1p-24 * std::abs(f.distance[i])) << i;
            EXPECT_EQ(g.gradient[i].x, double(float(f.gradient[i].x)));
            EXPECT_EQ(g.gradient[i].y, double(float(f.gradient[i].y)));
            EXPECT_EQ(g.gradient[i].z, double(float(f.gradient[i].z)));
        }
        EXPECT_EQ(g.closest_triangle, f.closest_triangle);  // int32 on disk: exact
        EXPECT_EQ(g.lattice.origin, f.lattice.origin);      // the header stays double
    }
}

TEST_F(FieldFiles, HeaderAndChannelFilesAsDocumented) {
    const SampledField f = make_field(LatticeType::BCC, {3, 4, 5});
    write_field(at("x.json"), f);
    const int64_t n = 60 + 24;
    EXPECT_EQ(sorted_entries(dir_), (std::vector<std::string>{"x.closest_triangle.raw", "x.distance.raw", "x.gradient.raw",
                                                       "x.json"}));
    EXPECT_EQ(fs::file_size(dir_ / "x.distance.raw"), uintmax_t(n * 4));
    EXPECT_EQ(fs::file_size(dir_ / "x.gradient.raw"), uintmax_t(n * 12));
    EXPECT_EQ(fs::file_size(dir_ / "x.closest_triangle.raw"), uintmax_t(n * 4));
    const json h = read_json(dir_ / "x.json");
    EXPECT_EQ(h.at("format"), "sdf-lattice-field");
    EXPECT_EQ(h.at("version"), 1);
    EXPECT_EQ(h.at("value_channel"), "distance");
    EXPECT_EQ(h.at("gradient_channel"), "gradient");
    EXPECT_EQ(h.at("lattice").at("type"), "bcc");
    EXPECT_EQ(h.at("lattice").at("resolution"), (json{3, 4, 10}));  // thesis notation
    EXPECT_EQ(h.at("lattice").at("notation"), "3x4x10");
    EXPECT_EQ(h.at("lattice").at("points"), n);
    EXPECT_EQ(h.at("channels").at("distance").at("file"), "x.distance.raw");  // relative to the header
    EXPECT_EQ(h.at("channels").at("distance").at("dtype"), "float32");
    EXPECT_EQ(h.at("channels").at("gradient").at("components"), 3);
    EXPECT_EQ(h.at("channels").at("closest_triangle").at("dtype"), "int32");
    // The raw bytes are the little-endian floats, x fastest.
    const std::string raw = read_text(dir_ / "x.distance.raw");
    float first = 0, last = 0;
    std::memcpy(&first, raw.data(), 4);
    std::memcpy(&last, raw.data() + 4 * (n - 1), 4);
    EXPECT_EQ(first, float(f.distance.front()));
    EXPECT_EQ(last, float(f.distance.back()));
}

TEST_F(FieldFiles, WithoutGradientOrClosestTriangle) {
    const SampledField f = make_field(LatticeType::CC, {3, 3, 3}, /*gradient=*/false);
    FieldWriteOptions o;
    o.closest_triangle = false;
    write_field(at("v.json"), f, o);
    EXPECT_EQ(sorted_entries(dir_), (std::vector<std::string>{"v.distance.raw", "v.json"}));
    const json h = read_json(dir_ / "v.json");
    EXPECT_FALSE(h.contains("gradient_channel"));
    const SampledField g = read_field(at("v.json"));
    EXPECT_EQ(g.size(), 27);
    EXPECT_TRUE(g.gradient.empty());
    EXPECT_TRUE(g.closest_triangle.empty());
}

TEST_F(FieldFiles, HeaderPathWithoutJsonSuffixGetsOne) {
    write_field(at("plain"), make_field(LatticeType::CC, {2, 2, 2}));
    EXPECT_TRUE(fs::exists(dir_ / "plain.json"));
    EXPECT_EQ(read_field(at("plain.json")).size(), 8);
}

TEST_F(FieldFiles, WriteCreatesMissingDirectories) {
    write_field(at("a/b/c/f.json"), make_field(LatticeType::CC, {2, 2, 2}));
    EXPECT_EQ(read_field(at("a/b/c/f.json")).size(), 8);
}

// ---- never silently overwritten -----------------------------------------------------------

TEST_F(FieldFiles, RefusesToOverwriteAndLeavesTheOldFieldIntact) {
    const SampledField f = make_field(LatticeType::CC, {3, 3, 3});
    write_field(at("f.json"), f);
    const std::string before_header = read_text(dir_ / "f.json");
    const std::string before_data = read_text(dir_ / "f.distance.raw");
    SampledField other = f;
    for (double& d : other.distance) d += 1;
    const std::string msg = error_of([&] { write_field(at("f.json"), other); });
    EXPECT_TRUE(Contains(msg, at("f.json")));
    EXPECT_TRUE(Contains(msg, "already exists"));
    EXPECT_EQ(read_text(dir_ / "f.json"), before_header);
    EXPECT_EQ(read_text(dir_ / "f.distance.raw"), before_data);
    // Explicitly allowed: replaced.
    FieldWriteOptions o;
    o.overwrite = Overwrite::Allow;
    write_field(at("f.json"), other, o);
    EXPECT_EQ(read_field(at("f.json")).distance[0], double(float(other.distance[0])));
}

TEST_F(FieldFiles, RefusesToClobberAStrayChannelFile) {
    // A user's file that happens to have a channel's name must not be replaced.
    write("g.distance.raw", "mine");
    const std::string msg = error_of([&] { write_field(at("g.json"), make_field(LatticeType::CC, {2, 2, 2})); });
    EXPECT_TRUE(Contains(msg, "g.distance.raw"));
    EXPECT_EQ(read_text(dir_ / "g.distance.raw"), "mine");
    EXPECT_FALSE(fs::exists(dir_ / "g.json"));
}

// Every target is checked before anything is written: a refused later channel leaves no
// earlier channel behind.
TEST_F(FieldFiles, RefusedWriteLeavesNoPartialChannels) {
    write("h.gradient.raw", "mine");
    const std::string msg = error_of([&] { write_field(at("h.json"), make_field(LatticeType::CC, {2, 2, 2})); });
    EXPECT_TRUE(Contains(msg, "h.gradient.raw"));
    EXPECT_EQ(read_text(dir_ / "h.gradient.raw"), "mine");
    EXPECT_FALSE(fs::exists(dir_ / "h.json"));
    EXPECT_FALSE(fs::exists(dir_ / "h.distance.raw"));
    write("k.closest_triangle.raw", "mine");
    EXPECT_ANY_THROW(write_field(at("k.json"), make_field(LatticeType::CC, {2, 2, 2})));
    EXPECT_EQ(sorted_entries(dir_), (std::vector<std::string>{"h.gradient.raw", "k.closest_triangle.raw"}));
}

// ---- fields written by a user -------------------------------------------------------------

TEST_F(FieldFiles, MinimalUserWrittenFieldReads) {
    std::vector<float> values(2 * 3 * 4);
    for (size_t i = 0; i < values.size(); ++i) values[i] = 0.25f * float(i) - 1.0f;
    write_raw(dir_ / "u.raw", values);
    write("u.json", R"({
  "format": "sdf-lattice-field", "version": 1,
  "lattice": {"type": "cc", "origin": [1, 2, 3], "spacing": 0.5, "resolution": [2, 3, 4]},
  "channels": {"value": {"file": "u.raw", "dtype": "float32"}},
  "value_channel": "value"
})");
    const SampledField f = read_field(at("u.json"));
    EXPECT_EQ(f.lattice.type, LatticeType::CC);
    EXPECT_EQ(f.lattice.resolution, (Int3{2, 3, 4}));
    EXPECT_EQ(f.lattice.origin, (Vec3d{1, 2, 3}));
    EXPECT_EQ(f.lattice.spacing, 0.5);
    ASSERT_EQ(f.size(), 24);
    for (size_t i = 0; i < values.size(); ++i) EXPECT_EQ(f.distance[i], double(values[i]));
    EXPECT_TRUE(f.gradient.empty());
    EXPECT_TRUE(f.closest_triangle.empty());
}

TEST_F(FieldFiles, UserFieldDefaultsAndExtraChannels) {
    // No value_channel (defaults to "value"), no dtype (float32), no type (cc); BCC float64
    // with free-form provenance and an extra channel that is ignored.
    std::vector<double> values(size_t(2 * 2 * 2 + 1));
    for (size_t i = 0; i < values.size(); ++i) values[i] = 1.0 / double(i + 3);
    write_raw(dir_ / "b.raw", values);
    write_raw(dir_ / "extra.raw", std::vector<float>(3, 0.f));
    write("b.json", R"({"format": "sdf-lattice-field", "version": 1,
  "lattice": {"type": "bcc", "origin": [0, 0, 0], "spacing": 1, "resolution": [2, 2, 4]},
  "channels": {"value": {"file": "b.raw", "dtype": "float64", "units": "mm", "description": "d"},
               "curvature": {"file": "extra.raw"}},
  "who": "a user", "when": [2026]})");
    const SampledField f = read_field(at("b.json"));
    EXPECT_EQ(f.lattice.type, LatticeType::BCC);
    EXPECT_EQ(f.lattice.resolution, (Int3{2, 2, 2}));
    EXPECT_EQ(f.distance, values);

    std::vector<float> cc(8, 0.5f);
    write_raw(dir_ / "c.raw", cc);
    write("c.json", R"({"format": "sdf-lattice-field", "version": 1,
  "lattice": {"origin": [0, 0, 0], "spacing": 1, "resolution": [2, 2, 2]},
  "channels": {"value": {"file": "c.raw"}}})");
    EXPECT_EQ(read_field(at("c.json")).distance, std::vector<double>(8, 0.5));
}

// ---- header errors ------------------------------------------------------------------------

/// Writes a CC 2x3x4 header with `lattice` and `channels` as given, and 24 floats in v.raw.
class BadHeaders : public FieldFiles {
protected:
    std::string header(const std::string& lattice, const std::string& channels, const std::string& extra = "") {
        write_raw(dir_ / "v.raw", std::vector<float>(24, 1.f));
        return write("h.json", "{\"format\": \"sdf-lattice-field\", \"version\": 1" +
                                   (lattice.empty() ? std::string() : ",\n \"lattice\": " + lattice) +
                                   ",\n \"channels\": " + channels + extra + "}");
    }
    const std::string good_lattice = R"({"type": "cc", "origin": [0, 0, 0], "spacing": 1, "resolution": [2, 3, 4]})";
    const std::string good_channels = R"({"value": {"file": "v.raw", "dtype": "float32"}})";
};

TEST_F(BadHeaders, GoodHeaderReads) { EXPECT_EQ(read_field(header(good_lattice, good_channels)).size(), 24); }

TEST_F(BadHeaders, WrongChannelSizeNamesFileAndByteCounts) {
    const std::string h = header(good_lattice, good_channels);
    write_raw(dir_ / "v.raw", std::vector<float>(23, 1.f));
    const std::string msg = error_of([&] { read_field(h); });
    EXPECT_TRUE(Contains(msg, h));
    EXPECT_TRUE(Contains(msg, "v.raw"));
    EXPECT_TRUE(Contains(msg, "92 bytes"));
    EXPECT_TRUE(Contains(msg, "need 96"));
    // float64 declared over float32 data: 192 bytes needed.
    write_raw(dir_ / "v.raw", std::vector<float>(24, 1.f));
    const std::string h64 = header(good_lattice, R"({"value": {"file": "v.raw", "dtype": "float64"}})");
    EXPECT_TRUE(Contains(error_of([&] { read_field(h64); }), "need 192"));
}

TEST_F(BadHeaders, UnknownDtypeNamesChannelKey) {
    const std::string h = header(good_lattice, R"({"value": {"file": "v.raw", "dtype": "float16"}})");
    const std::string msg = error_of([&] { read_field(h); });
    EXPECT_TRUE(Contains(msg, h));
    EXPECT_TRUE(Contains(msg, "'channels.value.dtype'"));
    EXPECT_TRUE(Contains(msg, "\"float16\""));
    EXPECT_TRUE(Contains(msg, "float32"));
}

TEST_F(BadHeaders, MissingLatticeOrLatticeKeys) {
    const std::string none = header("", good_channels);
    const std::string msg = error_of([&] { read_field(none); });
    EXPECT_TRUE(Contains(msg, none));
    EXPECT_TRUE(Contains(msg, "'lattice'"));
    EXPECT_TRUE(Contains(msg, "missing"));
    const std::string no_spacing = header(R"({"origin": [0, 0, 0], "resolution": [2, 3, 4]})", good_channels);
    const std::string m2 = error_of([&] { read_field(no_spacing); });
    EXPECT_TRUE(Contains(m2, "'lattice.spacing'"));
    EXPECT_TRUE(Contains(m2, "missing"));
    const std::string typo = header(R"({"origin": [0, 0, 0], "spacing": 1, "resolution": [2, 3, 4], "spacng": 2})",
                                    good_channels);
    EXPECT_TRUE(Contains(error_of([&] { read_field(typo); }), "did you mean 'spacing'?"));
}

TEST_F(BadHeaders, BccOddResolutionRejected) {
    const std::string h = header(R"({"type": "bcc", "origin": [0, 0, 0], "spacing": 1, "resolution": [2, 2, 3]})",
                                 good_channels);
    const std::string msg = error_of([&] { read_field(h); });
    EXPECT_TRUE(Contains(msg, h));
    EXPECT_TRUE(Contains(msg, "'lattice.resolution'"));
    EXPECT_TRUE(Contains(msg, "even"));
    EXPECT_TRUE(Contains(msg, "got [2,2,3]"));
}

TEST_F(BadHeaders, LatticeErrorsQuoteTheValueSeen) {
    for (const auto& [lattice, seen] : std::vector<std::pair<std::string, std::string>>{
             {R"({"origin": [0, 0], "spacing": 1, "resolution": [2, 3, 4]})", "got [0,0]"},
             {R"({"origin": [0, 0, 0], "spacing": -1, "resolution": [2, 3, 4]})", "got -1"},
             {R"({"origin": [0, 0, 0], "spacing": 1, "resolution": [2, 0, 4]})", "got [2,0,4]"}}) {
        const std::string msg = error_of([&] { read_field(header(lattice, good_channels)); });
        EXPECT_TRUE(Contains(msg, seen)) << lattice;
    }
}

TEST_F(BadHeaders, OtherLatticeErrors) {
    struct Case {
        std::string lattice, key;
    };
    for (const Case& c : std::vector<Case>{
             {R"({"origin": [0, 0], "spacing": 1, "resolution": [2, 3, 4]})", "'lattice.origin'"},
             {R"({"origin": [0, 0, 0], "spacing": -1, "resolution": [2, 3, 4]})", "'lattice.spacing'"},
             {R"({"origin": [0, 0, 0], "spacing": 0, "resolution": [2, 3, 4]})", "'lattice.spacing'"},
             {R"({"origin": [0, 0, 0], "spacing": 1, "resolution": [2, 0, 4]})", "'lattice.resolution'"},
             {R"({"origin": [0, 0, 0], "spacing": 1, "resolution": [2, 3]})", "'lattice.resolution'"},
             {R"({"type": "hex", "origin": [0, 0, 0], "spacing": 1, "resolution": [2, 3, 4]})", "'lattice.type'"},
             {R"([1, 2, 3])", "lattice"},
         }) {
        const std::string h = header(c.lattice, good_channels);
        const std::string msg = error_of([&] { read_field(h); });
        EXPECT_TRUE(Contains(msg, h)) << c.lattice;
        EXPECT_TRUE(Contains(msg, c.key)) << c.lattice;
    }
}

TEST_F(BadHeaders, ChannelErrors) {
    const std::string missing_file = header(good_lattice, R"({"value": {"file": "nope.raw"}})");
    const std::string m1 = error_of([&] { read_field(missing_file); });
    EXPECT_TRUE(Contains(m1, missing_file));
    EXPECT_TRUE(Contains(m1, "nope.raw"));
    const std::string wrong_name = header(good_lattice, good_channels, R"(, "value_channel": "distance")");
    const std::string m2 = error_of([&] { read_field(wrong_name); });
    EXPECT_TRUE(Contains(m2, "'value_channel'"));
    EXPECT_TRUE(Contains(m2, "'distance'"));
    const std::string comps = header(good_lattice, R"({"value": {"file": "v.raw", "components": 3}})");
    EXPECT_TRUE(Contains(error_of([&] { read_field(comps); }), "'channels.value.components'"));
    const std::string grad =
        header(good_lattice, R"({"value": {"file": "v.raw"}, "g": {"file": "v.raw"}})", R"(, "gradient_channel": "g")");
    EXPECT_TRUE(Contains(error_of([&] { read_field(grad); }), "'channels.g.components'"));
    const std::string typo = header(good_lattice, R"({"value": {"file": "v.raw", "dtpye": "float32"}})");
    EXPECT_TRUE(Contains(error_of([&] { read_field(typo); }), "did you mean 'dtype'?"));
}

// A channel "file" that is a directory: the error says so, not a size.
TEST_F(BadHeaders, ChannelFileIsADirectory) {
    fs::create_directories(dir_ / "adir.raw");
    const std::string h = header(good_lattice, R"({"value": {"file": "adir.raw"}})");
    const std::string msg = error_of([&] { read_field(h); });
    EXPECT_TRUE(Contains(msg, h));
    EXPECT_TRUE(Contains(msg, "adir.raw"));
    EXPECT_TRUE(Contains(msg, "is a directory, not a regular file")) << msg;
    EXPECT_FALSE(Contains(msg, "9223372036854775807"));
}

TEST_F(BadHeaders, FormatVersionAndSyntax) {
    write_raw(dir_ / "v.raw", std::vector<float>(24, 1.f));
    const std::string fmt = write("f.json", R"({"format": "nrrd", "version": 1, "lattice": {}, "channels": {}})");
    EXPECT_TRUE(Contains(error_of([&] { read_field(fmt); }), "'format'"));
    EXPECT_TRUE(Contains(error_of([&] { read_field(fmt); }), "got \"nrrd\""));
    const std::string ver = write("v.json", R"({"format": "sdf-lattice-field", "version": 2})");
    EXPECT_TRUE(Contains(error_of([&] { read_field(ver); }), "'version'"));
    EXPECT_TRUE(Contains(error_of([&] { read_field(ver); }), "got 2"));
    const std::string syn = write("s.json", "{\"format\": \"sdf-lattice-field\",\n \"version\": 1,,\n}");
    EXPECT_TRUE(Contains(error_of([&] { read_field(syn); }), syn + ":2:"));
    const std::string gone = at("absent.json");
    EXPECT_TRUE(Contains(error_of([&] { read_field(gone); }), gone));
}

// ---- NRRD -------------------------------------------------------------------------------

struct Nrrd {
    std::map<std::string, std::string> fields;
    std::string magic, data;
};

Nrrd parse_nrrd(const fs::path& p) {
    const std::string text = read_text(p);
    Nrrd n;
    const size_t end = text.find("\n\n");
    EXPECT_NE(end, std::string::npos) << "no blank line after the header";
    std::istringstream lines(text.substr(0, end));
    std::getline(lines, n.magic);
    for (std::string line; std::getline(lines, line);) {
        if (line.empty() || line[0] == '#') continue;
        const size_t colon = line.find(": ");
        EXPECT_NE(colon, std::string::npos) << line;
        if (colon != std::string::npos) n.fields[line.substr(0, colon)] = line.substr(colon + 2);
    }
    n.data = text.substr(end + 2);
    return n;
}

/// "(a,b,c)" -> {a, b, c}
std::vector<double> tuple_of(const std::string& s) {
    std::vector<double> v;
    std::string t = s;
    for (char& c : t)
        if (c == '(' || c == ')' || c == ',') c = ' ';
    std::istringstream in(t);
    for (double x; in >> x;) v.push_back(x);
    return v;
}

TEST_F(FieldFiles, NrrdHeaderAndDataOfACcField) {
    SampledField f = make_field(LatticeType::CC, {3, 4, 5});
    f.lattice.origin = {-1.0, 0.5, 2.0};
    f.lattice.spacing = 0.25;
    export_nrrd(at("f.nrrd"), f, true);
    const Nrrd n = parse_nrrd(dir_ / "f.nrrd");
    EXPECT_EQ(n.magic.substr(0, 4), "NRRD");
    EXPECT_EQ(n.fields.at("type"), "float");
    EXPECT_EQ(n.fields.at("dimension"), "3");
    EXPECT_EQ(n.fields.at("sizes"), "3 4 5");
    EXPECT_EQ(n.fields.at("endian"), "little");
    EXPECT_EQ(n.fields.at("encoding"), "raw");
    EXPECT_EQ(tuple_of(n.fields.at("space origin")), (std::vector<double>{-1.0, 0.5, 2.0}));
    EXPECT_EQ(tuple_of(n.fields.at("space directions")),
              (std::vector<double>{0.25, 0, 0, 0, 0.25, 0, 0, 0, 0.25}));
    EXPECT_TRUE(n.fields.count("space"));
    ASSERT_EQ(n.data.size(), 60u * 4u);
    for (size_t i = 0; i < 60; ++i) {
        float v;
        std::memcpy(&v, n.data.data() + 4 * i, 4);
        EXPECT_EQ(v, float(f.distance[i])) << i;
    }
    // The gradient: a 4-D volume, the vector axis first (fastest).
    const Nrrd g = parse_nrrd(dir_ / "f.gradient.nrrd");
    EXPECT_EQ(g.fields.at("dimension"), "4");
    EXPECT_EQ(g.fields.at("sizes"), "3 3 4 5");
    EXPECT_EQ(g.fields.at("kinds"), "vector domain domain domain");
    EXPECT_EQ(g.fields.at("endian"), "little");
    EXPECT_TRUE(Contains(g.fields.at("space directions"), "none"));
    ASSERT_EQ(g.data.size(), 60u * 12u);
    float gy;
    std::memcpy(&gy, g.data.data() + 4 * (3 * 17 + 1), 4);
    EXPECT_EQ(gy, float(f.gradient[17].y));
}

TEST_F(FieldFiles, NrrdExactSpacingAndOriginDigits) {
    SampledField f = make_field(LatticeType::CC, {2, 2, 2});  // origin -1/3, spacing 0.1 + 1e-12
    export_nrrd(at("p.nrrd"), f, false);
    const Nrrd n = parse_nrrd(dir_ / "p.nrrd");
    EXPECT_EQ(tuple_of(n.fields.at("space origin"))[0], f.lattice.origin.x);  // 17 digits round-trip
    EXPECT_EQ(tuple_of(n.fields.at("space directions"))[0], f.lattice.spacing);
    EXPECT_FALSE(fs::exists(dir_ / "p.gradient.nrrd"));
}

TEST_F(FieldFiles, NrrdRejectsBccAndExistingFiles) {
    const std::string msg = error_of([&] { export_nrrd(at("b.nrrd"), make_field(LatticeType::BCC, {3, 3, 3}), true); });
    EXPECT_TRUE(Contains(msg, "b.nrrd"));
    EXPECT_TRUE(Contains(msg, "CC"));
    EXPECT_TRUE(sorted_entries(dir_).empty());
    write("e.nrrd", "old");
    EXPECT_TRUE(Contains(error_of([&] { export_nrrd(at("e.nrrd"), make_field(LatticeType::CC, {2, 2, 2}), false); }),
                         "already exists"));
    EXPECT_EQ(read_text(dir_ / "e.nrrd"), "old");
}

// ---- 8-bit export -----------------------------------------------------------------------

TEST_F(FieldFiles, Uint8SurfaceIs127InsideHigherOutsideLower) {
    SampledField f;
    f.lattice = make_lattice(LatticeType::CC, {2, 2, 2});
    // max |d| = 2, scale 127/2 = 63.5; byte = clamp(round(127 - 63.5 d))
    f.distance = {0.0, -0.5, -2.0, 0.5, 2.0, 1.0, -1e-9, 1e-9};
    const double scale = export_uint8(at("u8.raw"), f);
    EXPECT_NEAR(scale, 63.5, 1e-15);
    const std::string b = read_text(dir_ / "u8.raw");
    ASSERT_EQ(b.size(), 8u);
    const std::vector<int> want = {127, 159, 254, 95, 0, 64, 127, 127};  // 158.75->159, 95.25->95, 63.5->64
    for (size_t i = 0; i < 8; ++i) EXPECT_EQ(int(uint8_t(b[i])), want[i]) << i;
    for (size_t i = 0; i < 8; ++i) {
        if (f.distance[i] < -1e-3) {
            EXPECT_GT(int(uint8_t(b[i])), 127) << i;
        }
        if (f.distance[i] > 1e-3) {
            EXPECT_LT(int(uint8_t(b[i])), 127) << i;
        }
    }
}

TEST_F(FieldFiles, Uint8AllZeroFieldAndOverwrite) {
    SampledField f;
    f.lattice = make_lattice(LatticeType::BCC, {2, 2, 2});
    f.distance.assign(9, 0.0);
    EXPECT_EQ(export_uint8(at("z.raw"), f), 1.0);
    EXPECT_EQ(read_text(dir_ / "z.raw"), std::string(9, char(127)));
    EXPECT_TRUE(Contains(error_of([&] { export_uint8(at("z.raw"), f); }), "already exists"));
}

// ---- write_file_atomically --------------------------------------------------------------

TEST_F(FieldFiles, AtomicWriteLeavesOnlyTheTarget) {
    const std::string data = std::string("binary\0data", 11);
    write_file_atomically(at("a.bin"), data.data(), data.size());
    EXPECT_EQ(read_text(dir_ / "a.bin"), data);
    EXPECT_EQ(sorted_entries(dir_), (std::vector<std::string>{"a.bin"}));
    write_text_atomically(at("sub/dir/t.txt"), "text");  // parents are created
    EXPECT_EQ(read_text(dir_ / "sub/dir/t.txt"), "text");
    EXPECT_EQ(sorted_entries(dir_ / "sub/dir"), (std::vector<std::string>{"t.txt"}));
    write_text_atomically(at("empty"), "");
    EXPECT_EQ(fs::file_size(dir_ / "empty"), 0u);
}

TEST_F(FieldFiles, AtomicWriteRefusesExistingUnlessAllowed) {
    write_text_atomically(at("r.txt"), "first");
    const std::string msg = error_of([&] { write_text_atomically(at("r.txt"), "second"); });
    EXPECT_TRUE(Contains(msg, at("r.txt")));
    EXPECT_TRUE(Contains(msg, "refusing to overwrite"));
    EXPECT_EQ(read_text(dir_ / "r.txt"), "first");
    write_text_atomically(at("r.txt"), "second", Overwrite::Allow);
    EXPECT_EQ(read_text(dir_ / "r.txt"), "second");
    EXPECT_EQ(sorted_entries(dir_), (std::vector<std::string>{"r.txt"}));
}

// A failed final rename (here: the target is a directory) must not leave the temporary file.
TEST_F(FieldFiles, FailedAtomicWriteLeavesNoTemporaryFile) {
    fs::create_directories(dir_ / "target");
    fs::create_directories(dir_ / "target/keep");
    EXPECT_ANY_THROW(write_text_atomically(at("target"), "x", Overwrite::Allow));
    EXPECT_ANY_THROW(write_text_atomically(at("target"), "x", Overwrite::Forbid));
    EXPECT_TRUE(fs::is_directory(dir_ / "target/keep"));
    EXPECT_EQ(sorted_entries(dir_), std::vector<std::string>{"target"});
}

// Writers racing for one name: exactly one wins, nobody's file is replaced, and no
// temporary is left behind (temporaries are unique per thread).
TEST_F(FieldFiles, ConcurrentAtomicWritesNeverReplace) {
    constexpr int kThreads = 8;
    std::vector<std::thread> threads;
    std::atomic<int> won{0}, refused{0};
    for (int t = 0; t < kThreads; ++t)
        threads.emplace_back([&, t] {
            try {
                write_text_atomically(at("race.txt"), "writer " + std::to_string(t));
                ++won;
            } catch (const std::exception& e) {
                if (Contains(e.what(), "already exists")) ++refused;
            }
        });
    for (auto& th : threads) th.join();
    EXPECT_EQ(won.load(), 1);
    EXPECT_EQ(refused.load(), kThreads - 1);
    EXPECT_EQ(sorted_entries(dir_), std::vector<std::string>{"race.txt"});
    EXPECT_TRUE(Contains(read_text(dir_ / "race.txt"), "writer "));
}

TEST_F(FieldFiles, RenameNoReplaceRefusesExistingFilesAndDirectories) {
    write("a", "a");
    write("b", "b");
    EXPECT_FALSE(rename_no_replace(at("a"), at("b")));
    EXPECT_EQ(read_text(dir_ / "b"), "b");
    fs::create_directories(dir_ / "d1");
    fs::create_directories(dir_ / "d2");  // empty: rename(2) would replace it
    EXPECT_FALSE(rename_no_replace(at("d1"), at("d2")));
    EXPECT_TRUE(fs::exists(dir_ / "d1"));
    EXPECT_TRUE(rename_no_replace(at("a"), at("c")));
    EXPECT_EQ(read_text(dir_ / "c"), "a");
}

// ---- StagedDirectory ----------------------------------------------------------------------

TEST_F(FieldFiles, StagedDirectoryCommitMovesIntoPlace) {
    const std::string final_path = at("runs/r1");
    {
        StagedDirectory s(final_path);
        EXPECT_EQ(s.final_path(), final_path);
        EXPECT_NE(s.path(), final_path);
        EXPECT_TRUE(fs::is_directory(s.path()));
        EXPECT_EQ(fs::path(s.path()).parent_path(), fs::path(final_path).parent_path());  // same file system
        EXPECT_EQ(fs::path(s.path()).filename().string()[0], '.');                         // hidden
        EXPECT_FALSE(fs::exists(final_path));
        write_text_atomically(s.path() + "/m.json", "{}");
        s.commit();
        EXPECT_TRUE(fs::exists(final_path + "/m.json"));
        EXPECT_FALSE(fs::exists(s.path()));
    }
    EXPECT_EQ(read_text(final_path + "/m.json"), "{}");  // the destructor keeps a committed run
    EXPECT_EQ(sorted_entries(dir_ / "runs"), (std::vector<std::string>{"r1"}));
}

TEST_F(FieldFiles, StagedDirectoryWithoutCommitLeavesNothing) {
    const std::string final_path = at("runs/r2");
    std::string staged;
    try {
        StagedDirectory s(final_path);
        staged = s.path();
        write_text_atomically(s.path() + "/fields/partial.raw", "half");
        throw std::runtime_error("interrupted");
    } catch (const std::runtime_error&) {
    }
    EXPECT_FALSE(fs::exists(staged));
    EXPECT_FALSE(fs::exists(final_path));
    EXPECT_TRUE(sorted_entries(dir_ / "runs").empty());
}

TEST_F(FieldFiles, StagedDirectoryRefusesAnExistingFinalPath) {
    fs::create_directories(dir_ / "runs/r3");
    write("runs/r3/old.json", "old");
    const std::string msg = error_of([&] { StagedDirectory s(at("runs/r3")); });
    EXPECT_TRUE(Contains(msg, at("runs/r3")));
    EXPECT_TRUE(Contains(msg, "already exists"));
    EXPECT_EQ(sorted_entries(dir_ / "runs"), (std::vector<std::string>{"r3"}));
    EXPECT_EQ(read_text(dir_ / "runs/r3/old.json"), "old");
}

TEST_F(FieldFiles, StagedDirectoryCommitRefusesAFinalPathThatAppeared) {
    const std::string final_path = at("runs/r4");
    {
        StagedDirectory s(final_path);
        write_text_atomically(s.path() + "/new.json", "new");
        fs::create_directories(final_path);
        write_text_atomically(final_path + "/other.json", "other");
        const std::string msg = error_of([&] { s.commit(); });
        EXPECT_TRUE(Contains(msg, final_path));
    }
    EXPECT_EQ(sorted_entries(final_path), (std::vector<std::string>{"other.json"}));
    EXPECT_EQ(sorted_entries(dir_ / "runs"), (std::vector<std::string>{"r4"}));  // staging removed
}

// A trailing slash (or "." components) is normalised away: staging happens beside the final
// path, never inside it.
TEST_F(FieldFiles, StagedDirectoryWithTrailingSlash) {
    const std::string final_path = at("runs/r5") + "/";
    {
        StagedDirectory s(final_path);
        EXPECT_EQ(s.final_path(), at("runs/r5"));
        EXPECT_EQ(fs::path(s.path()).parent_path(), dir_ / "runs");
        write_text_atomically(s.path() + "/m.json", "{}");
        s.commit();
    }
    EXPECT_TRUE(fs::exists(dir_ / "runs/r5/m.json"));
    EXPECT_EQ(sorted_entries(dir_ / "runs"), (std::vector<std::string>{"r5"}));
}

// commit() never replaces an existing directory, not even an empty one (rename(2) would).
TEST_F(FieldFiles, StagedDirectoryNeverReplacesAnEmptyDirectory) {
    const std::string final_path = at("runs/r6");
    {
        StagedDirectory s(final_path);
        write_text_atomically(s.path() + "/new.json", "new");
        fs::create_directories(final_path);  // empty
        EXPECT_TRUE(Contains(error_of([&] { s.commit(); }), "refusing to overwrite"));
        EXPECT_TRUE(s.try_commit_as(at("runs/r6-2")));
        EXPECT_EQ(s.final_path(), at("runs/r6-2"));
    }
    EXPECT_TRUE(fs::is_empty(final_path));
    EXPECT_EQ(read_text(dir_ / "runs/r6-2/new.json"), "new");
    EXPECT_EQ(sorted_entries(dir_ / "runs"), (std::vector<std::string>{"r6", "r6-2"}));
}

}  // namespace
}  // namespace sdf
