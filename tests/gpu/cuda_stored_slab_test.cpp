// The CUDA BVH sampler's stored slabs (core/sampling/stored_slab.h): the bytes it makes on
// the device equal, byte for byte, what the field writer makes of sample_slab()'s field
// (field_channel_bytes), on CC and BCC lattices (both strategies), whole and in slabs, cut
// into many GPU pieces, float32 and float64, with and without the gradient and triangle
// channels, with and without a narrow band (whose counts must match too).
#include <gtest/gtest.h>

#include <cstring>

#include "core/lattice/lattice_fitting.h"
#include "core/sampling/narrow_band.h"
#include "harness/io/field_file.h"
#include "harness/sampling/sampler_table.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

SamplerOptions gpu_options(Precision precision, BccStrategy strategy, double band) {
    SamplerOptions o;
    o.backend = "cuda";
    o.method = "bvh";
    o.precision = precision;
    o.bcc_strategy = strategy;
    o.band_width = band;
    o.progress = false;
    o.max_points_per_piece = 3000;  // several pieces per slab
    return o;
}

/// The field writer's channel files for `layout` (names and dtypes), as streamed sampling plans them.
std::vector<FieldChannelFile> channels_of(const StoredLayout& layout) {
    const FieldDtype dtype = layout.float32 ? FieldDtype::Float32 : FieldDtype::Float64;
    std::vector<FieldChannelFile> c = {{"distance", "d.raw", dtype, 1}};
    if (layout.gradient) c.push_back({"gradient", "g.raw", dtype, 3});
    if (layout.closest_triangle) c.push_back({"closest_triangle", "t.raw", dtype, 1});
    return c;
}

const char* stored_bytes(const StoredSlab& s, const std::string& name) {
    return name == "distance" ? s.distance : name == "gradient" ? s.gradient : s.closest_triangle;
}

TEST(CudaStoredSlab, EqualsTheWrittenBytesOfSampleSlab) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[4].mesh;  // soccer ball
    const Lattice cc = fit_lattice(LatticeType::CC, {21, 22, 23}, mesh.bounds(), 0.1);
    const Lattice bcc = fit_lattice(LatticeType::BCC, {17, 18, 19}, mesh.bounds(), 0.1);
    const StoredLayout layouts[] = {{true, true, true}, {false, false, true}, {true, true, false}, {false, true, true}};
    int compared = 0;
    for (const Lattice& lattice : {cc, bcc})
        for (BccStrategy strategy : {BccStrategy::TwoGrids, BccStrategy::DoubleResolution}) {
            if (lattice.type == LatticeType::CC && strategy == BccStrategy::DoubleResolution) continue;
            for (Precision precision : {Precision::Float, Precision::Double})
                for (double band : {0.0, 0.05}) {
                    auto sampler = make_sampler(gpu_options(precision, strategy, band));
                    for (const LatticeSlab slab : {whole_lattice_slab(lattice), LatticeSlab{3, 9}})
                        for (const StoredLayout& layout : layouts) {
                            const std::string what = lattice_notation(lattice) + " " + bcc_strategy_name(strategy) + " " +
                                                     precision_name(precision) + " band " + std::to_string(band) + " slab " +
                                                     std::to_string(slab.z_begin) + ".." + std::to_string(slab.z_end) +
                                                     (layout.float32 ? " float32" : " float64") + (layout.gradient ? " +g" : "") +
                                                     (layout.closest_triangle ? " +t" : "");
                            const SampledField field = sampler->bind(share(mesh))->sample_slab(lattice, slab);
                            const std::optional<StoredSlab> stored = sampler->bind(share(mesh))->sample_slab_stored(lattice, slab, layout);
                            ASSERT_TRUE(stored.has_value()) << what;
                            ASSERT_EQ(stored->points, field.size()) << what;
                            EXPECT_EQ(stored->info.sampler.details.at("stored_on_device"), true) << what;
                            EXPECT_EQ(stored->info.sampler.points_computed, field.sampler.points_computed) << what;
                            if (band > 0) {
                                const NarrowBandCounts counts = count_narrow_band(field);
                                EXPECT_EQ(stored->band.outside, counts.outside) << what;
                                EXPECT_EQ(stored->band.in_band, counts.in_band) << what;
                                EXPECT_GT(counts.outside, 0) << what;
                                EXPECT_EQ(nlohmann::json(stored->info.sampler).at("band"), nlohmann::json(field.sampler).at("band")) << what;
                            }
                            for (const FieldChannelFile& c : channels_of(layout)) {
                                const std::vector<char> truth = field_channel_bytes(field, c, 0, size_t(field.size()));
                                const char* bytes = stored_bytes(*stored, c.name);
                                ASSERT_NE(bytes, nullptr) << what << " " << c.name;
                                EXPECT_EQ(std::memcmp(bytes, truth.data(), truth.size()), 0) << what << " " << c.name;
                                ++compared;
                            }
                            if (!layout.gradient) {
                                EXPECT_EQ(stored->gradient, nullptr) << what;
                            }
                            if (!layout.closest_triangle) {
                                EXPECT_EQ(stored->closest_triangle, nullptr) << what;
                            }
                        }
                }
        }
    EXPECT_EQ(compared, 3 * 2 * 2 * 2 * (3 + 2 + 2 + 3));
}

TEST(CudaStoredSlab, AHeldSlabKeepsItsBytesWhileTheNextIsSampled) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[4].mesh;
    const Lattice lattice = fit_lattice(LatticeType::CC, {20, 20, 20}, mesh.bounds(), 0.1);
    auto sampler = make_sampler(gpu_options(Precision::Float, BccStrategy::TwoGrids, 0.0));
    const StoredLayout layout;
    const StoredSlab first = *sampler->bind(share(mesh))->sample_slab_stored(lattice, {0, 10}, layout);
    const std::vector<char> copy(first.distance, first.distance + first.points * 4);
    const StoredSlab second = *sampler->bind(share(mesh))->sample_slab_stored(lattice, {10, 20}, layout);
    const StoredSlab third = *sampler->bind(share(mesh))->sample_slab_stored(lattice, {5, 15}, layout);
    EXPECT_NE(first.distance, second.distance);  // first is still held: another buffer
    EXPECT_NE(first.distance, third.distance);
    EXPECT_EQ(std::memcmp(first.distance, copy.data(), copy.size()), 0);
}

}  // namespace
}  // namespace sdf
