// Volume formats: the name table, the files a CC and a BCC field become, the .npy bytes
// parsed by hand, and the refusals (existing files, inconsistent fields, .vdb without
// OpenVDB). The values read back by pyopenvdb, VTK and NumPy are checked in
// tests/python/test_volume_formats.py.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "harness/io/volume_formats.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;
using test::Contains;
using test::error_of;
using test::read_text;
using test::sorted_entries;

SampledField make_field(LatticeType type, Int3 res) {
    SampledField f;
    f.lattice.type = type;
    f.lattice.resolution = res;
    f.lattice.origin = {-1.0 / 3.0, 0.1, 2.0};
    f.lattice.spacing = 0.25;
    f.resize(f.lattice.num_points());
    for (size_t i = 0; i < f.distance.size(); ++i) {
        f.distance[i] = std::sin(0.37 * double(i)) / 3.0;
        f.gradient[i] = {0.0, 0.6, -0.8};
    }
    return f;
}

class VolumeFormats : public test::ScratchDirTest {
protected:
    VolumeFormats() : ScratchDirTest("sdf_volume_formats_test") {}
};

TEST(VolumeFormatTable, NamesRoundTripAndUnknownNamesListTheKnownOnes) {
    for (const VolumeFormatInfo& f : kVolumeFormats) EXPECT_EQ(volume_format_from_name(f.name), f.format);
    EXPECT_EQ(volume_format_names(), "vdb, vti, npy, npz");
    EXPECT_TRUE(Contains(error_of([] { volume_format_from_name("vtk"); }), "\"vtk\"; expected one of vdb, vti, npy, npz"));
    EXPECT_TRUE(volume_format_available(VolumeFormat::Vti));
}

TEST(VolumeFormatFiles, BccFieldsBecomeTheirTwoSubGrids) {
    const SampledField cc = make_field(LatticeType::CC, {3, 3, 3}), bcc = make_field(LatticeType::BCC, {3, 3, 3});
    EXPECT_EQ(volume_files(cc, "d/f.vti", VolumeFormat::Vti), std::vector<std::string>{"d/f.vti"});
    EXPECT_EQ(volume_files(bcc, "d/f.vti", VolumeFormat::Vti),
              (std::vector<std::string>{"d/f.primary.vti", "d/f.secondary.vti"}));
    EXPECT_EQ(volume_files(cc, "d/f", VolumeFormat::Npy), (std::vector<std::string>{"d/f.npy", "d/f.gradient.npy"}));
    EXPECT_EQ(volume_files(bcc, "d/f.npy", VolumeFormat::Npy),
              (std::vector<std::string>{"d/f.primary.npy", "d/f.primary.gradient.npy", "d/f.secondary.npy",
                                        "d/f.secondary.gradient.npy"}));
    EXPECT_EQ(volume_files(bcc, "d/f.vdb", VolumeFormat::Vdb), std::vector<std::string>{"d/f.vdb"});
    EXPECT_EQ(volume_files(bcc, "d/f.npz", VolumeFormat::Npz), std::vector<std::string>{"d/f.npz"});
}

TEST_F(VolumeFormats, NpyIsVersion1WithA64ByteAlignedHeaderAndTheValuesAsFloat) {
    const SampledField f = make_field(LatticeType::BCC, {3, 4, 5});
    write_field_as(f, at("b.npy"), VolumeFormat::Npy);
    const std::string bytes = read_text(dir_ / "b.secondary.npy");
    ASSERT_EQ(bytes.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
    uint16_t length = 0;
    std::memcpy(&length, bytes.data() + 8, 2);
    EXPECT_EQ((10 + length) % 64, 0);
    const std::string header = bytes.substr(10, length);
    EXPECT_TRUE(Contains(header, "'descr': '<f4', 'fortran_order': False, 'shape': (4, 3, 2), }"));
    ASSERT_EQ(bytes.size(), 10u + length + 4 * 3 * 2 * sizeof(float));
    const int64_t first = f.lattice.primary_count();
    for (int64_t i = 0; i < 24; ++i) {
        float v = 0;
        std::memcpy(&v, bytes.data() + 10 + length + 4 * i, 4);
        EXPECT_EQ(v, float(f.distance[size_t(first + i)])) << i;
    }
}

TEST_F(VolumeFormats, ExistingFilesAreRefusedBeforeAnythingIsWritten) {
    const SampledField f = make_field(LatticeType::BCC, {3, 3, 3});
    fs::create_directories(dir_ / "out");
    std::ofstream(dir_ / "out" / "b.secondary.vti") << "old";
    EXPECT_TRUE(Contains(error_of([&] { write_field_as(f, at("out/b.vti"), VolumeFormat::Vti); }),
                         "b.secondary.vti: already exists"));
    EXPECT_EQ(sorted_entries(dir_ / "out"), std::vector<std::string>{"b.secondary.vti"});
    EXPECT_EQ(read_text(dir_ / "out" / "b.secondary.vti"), "old");
    VolumeWriteOptions o;
    o.overwrite = Overwrite::Allow;
    EXPECT_EQ(write_field_as(f, at("out/b.vti"), VolumeFormat::Vti, o).size(), 2u);
    EXPECT_NE(read_text(dir_ / "out" / "b.secondary.vti"), "old");
}

TEST_F(VolumeFormats, AFieldWhoseSizesDisagreeWithItsLatticeIsRefused) {
    SampledField f = make_field(LatticeType::CC, {3, 3, 3});
    f.distance.pop_back();
    EXPECT_TRUE(Contains(error_of([&] { write_field_as(f, at("c.npz"), VolumeFormat::Npz); }),
                         "c.npz: the field holds 26 distances but its lattice has 27 points"));
    EXPECT_TRUE(sorted_entries(dir_).empty());
}

TEST_F(VolumeFormats, VdbNeedsOpenVdbAndAPositiveBand) {
    const SampledField f = make_field(LatticeType::CC, {3, 3, 3});
    if (!volume_format_available(VolumeFormat::Vdb)) {
        EXPECT_TRUE(Contains(error_of([&] { write_field_as(f, at("c.vdb"), VolumeFormat::Vdb); }),
                             "built without OpenVDB (install libopenvdb-dev"));
        return;
    }
    VolumeWriteOptions o;
    o.vdb_band = 0;
    EXPECT_TRUE(Contains(error_of([&] { write_field_as(f, at("c.vdb"), VolumeFormat::Vdb, o); }),
                         "c.vdb: the OpenVDB band must be a positive number of spacings, got 0"));
    EXPECT_TRUE(sorted_entries(dir_).empty());
    EXPECT_EQ(write_field_as(f, at("c.vdb"), VolumeFormat::Vdb), std::vector<std::string>{at("c.vdb")});
    EXPECT_EQ(sorted_entries(dir_), std::vector<std::string>{"c.vdb"});  // no temporary left
}

}  // namespace
}  // namespace sdf
