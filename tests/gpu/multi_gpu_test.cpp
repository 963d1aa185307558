// Several GPUs (issue 36), where they are: skipped (77) below two visible devices. Every
// CUDA object on its device: a sampler on device 1 gives device 0's bytes (its events and
// buffers were made on device 0 before, cudaErrorInvalidResourceHandle); samplers on both
// devices used at once from two threads; and "devices" [0, 1] in one process gives one
// device's fields (CC, BCC, with a band), point queries and host queries byte for byte, for
// the BVH and the brute-force samplers, its report naming the device of each slab.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <thread>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/sampling/point_sets.h"
#include "cuda/util/cuda_device.h"
#include "harness/sampling/sampler_table.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

std::shared_ptr<const PreparedMesh> torus() {
    static const auto mesh = share(prepare_mesh(make_torus(1.0, 0.35, 160, 64)));
    return mesh;
}

SamplerOptions on(const std::string& method, int device) {
    SamplerOptions o;
    o.backend = "cuda";
    o.method = method;
    o.device = device;
    o.progress = false;
    return o;
}

void expect_same_bytes(const SampledField& a, const SampledField& b, const std::string& what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    const size_t n = size_t(a.size());
    EXPECT_EQ(0, std::memcmp(a.distance.data(), b.distance.data(), n * sizeof(double))) << what;
    EXPECT_EQ(0, std::memcmp(a.gradient.data(), b.gradient.data(), n * sizeof(Vec3d))) << what;
    EXPECT_EQ(0, std::memcmp(a.closest_triangle.data(), b.closest_triangle.data(), n * sizeof(int32_t))) << what;
}

std::vector<Lattice> lattices() {
    return {fit_lattice(LatticeType::CC, {96, 96, 96}, torus()->bounds(), 0.1),
            fit_lattice(LatticeType::BCC, {64, 64, 128}, torus()->bounds(), 0.1)};
}

TEST(MultiGpu, EachDeviceAloneGivesTheSameBytes) {
    for (const std::string method : {"bvh", "brute_force"}) {
        const Lattice lattice = lattices()[0];
        const SampledField zero = make_sampler(on(method, 0))->bind(torus())->sample(lattice);
        const SampledField one = make_sampler(on(method, 1))->bind(torus())->sample(lattice);
        expect_same_bytes(zero, one, method + " device 1");
        EXPECT_EQ(one.sampler.details.at("device").at("index"), 1);
        EXPECT_NE(one.sampler.details.at("device").at("pci_bus_id"), zero.sampler.details.at("device").at("pci_bus_id"));
    }
}

TEST(MultiGpu, SamplersOnBothDevicesAtOnceFromTwoThreads) {
    const Lattice lattice = lattices()[1];
    const SampledField reference = make_sampler(on("bvh", 0))->bind(torus())->sample(lattice);
    // Bound on this thread, used on others (a Python SDF made in one thread, queried in another).
    const auto zero = make_sampler(on("bvh", 0))->bind(torus());
    const auto one = make_sampler(on("bvh", 1))->bind(torus());
    SampledField a, b;
    std::thread ta([&] { a = one->sample(lattice); });
    std::thread tb([&] { b = zero->sample(lattice); });
    ta.join();
    tb.join();
    expect_same_bytes(reference, a, "device 1 on a thread");
    expect_same_bytes(reference, b, "device 0 on a thread");
}

TEST(MultiGpu, TwoDevicesInOneProcessGiveOneDevicesBytes) {
    for (const std::string method : {"bvh", "brute_force"})
        for (const Lattice& lattice : lattices())
            for (const double band : {0.0, 0.02}) {
                SamplerOptions one = on(method, 0);
                one.band_width = band;
                SamplerOptions two = one;
                two.devices.list = {0, 1};
                two.min_points_per_device = 1;  // split these small lattices (the default keeps them on one GPU)
                const std::string what = method + " " + lattice_type_name(lattice.type) + " band " + std::to_string(band);
                const SampledField a = make_sampler(one)->bind(torus())->sample(lattice);
                const SampledField b = make_sampler(two)->bind(torus())->sample(lattice);
                expect_same_bytes(a, b, what);
                const nlohmann::json& d = b.sampler.details.at("devices");
                ASSERT_TRUE(d.at("split").get<bool>()) << what << d;
                ASSERT_EQ(d.at("parts").size(), 2u) << what;
                EXPECT_EQ(d.at("parts")[0].at("device").at("index"), 0);
                EXPECT_EQ(d.at("parts")[1].at("device").at("index"), 1);
                if (band == 0) {
                    EXPECT_EQ(b.sampler.points_computed, a.sampler.points_computed) << what;
                }
            }
}

// The split threshold's default: a lattice too small to pay for a split runs on device 0,
// and the report says why (SamplerOptions::min_points_per_device).
TEST(MultiGpu, ASmallJobStaysOnOneDeviceAndSaysWhy) {
    const Lattice lattice = lattices()[0];  // 96^3: 884,736 points, below 2 x 2^23
    SamplerOptions two = on("bvh", 0);
    two.devices.list = {0, 1};
    const SampledField a = make_sampler(on("bvh", 0))->bind(torus())->sample(lattice);
    const SampledField b = make_sampler(two)->bind(torus())->sample(lattice);
    expect_same_bytes(a, b, "unsplit");
    const nlohmann::json& d = b.sampler.details.at("devices");
    EXPECT_FALSE(d.at("split").get<bool>()) << d;
    EXPECT_EQ(d.at("used"), 1);
    EXPECT_NE(d.at("why_not").get<std::string>().find("884736 points, fewer than 2 x 8388608"), std::string::npos) << d;
}

// sdf-sample's path: the slab's bytes as the field file stores them, made on each device.
TEST(MultiGpu, TwoDevicesStoreOneDevicesFileBytes) {
    for (const Lattice& lattice : lattices())
        for (const bool float32 : {true, false}) {
            const StoredLayout layout{float32, true, true};
            SamplerOptions two = on("bvh", 0);
            two.devices.list = {0, 1};
            two.min_points_per_device = 1;
            const LatticeSlab slab{5, lattice.resolution.z - 3};
            const auto a = make_sampler(on("bvh", 0))->bind(torus())->sample_slab_stored(lattice, slab, layout);
            const auto b = make_sampler(two)->bind(torus())->sample_slab_stored(lattice, slab, layout);
            ASSERT_TRUE(a && b);
            ASSERT_EQ(a->points, b->points);
            const size_t n = size_t(a->points), vb = layout.value_bytes();
            EXPECT_EQ(0, std::memcmp(a->distance, b->distance, n * vb));
            EXPECT_EQ(0, std::memcmp(a->gradient, b->gradient, 3 * n * vb));
            EXPECT_EQ(0, std::memcmp(a->closest_triangle, b->closest_triangle, n * 4));
            EXPECT_TRUE(b->info.sampler.details.at("devices").at("split").get<bool>());
        }
}

TEST(MultiGpu, TwoDevicesAnswerPointQueriesAsOne) {
    const std::vector<Vec3d> points =
        make_point_set(*torus(), PointSetSpec{PointSetKind::GaussianSurface, 1'000'003, 0.02, 0.1, 11});
    SamplerOptions two = on("bvh", 0);
    two.devices.all = true;
    two.min_points_per_device = 1;
    const auto one_bound = make_sampler(on("bvh", 0))->bind(torus());
    const auto two_bound = make_sampler(two)->bind(torus());
    const std::vector<PointSample> a = one_bound->query(points);
    const std::vector<PointSample> b = two_bound->query(points);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {  // member by member: PointSample has padding
        ASSERT_EQ(0, std::memcmp(&a[i].distance, &b[i].distance, sizeof(double))) << i;
        ASSERT_EQ(0, std::memcmp(&a[i].gradient, &b[i].gradient, sizeof(Vec3d))) << i;
        ASSERT_EQ(a[i].triangle, b[i].triangle) << i;
    }
    const HostPoints host{points.data(), false, int64_t(points.size()), 3, 1};
    std::vector<double> d1(points.size()), d2(points.size()), g1(3 * points.size()), g2(3 * points.size());
    std::vector<int32_t> t1(points.size()), t2(points.size());
    one_bound->query_host(host, {d1.data(), g1.data(), t1.data()});
    two_bound->query_host(host, {d2.data(), g2.data(), t2.data()});
    EXPECT_EQ(0, std::memcmp(d1.data(), d2.data(), d1.size() * sizeof(double)));
    EXPECT_EQ(0, std::memcmp(g1.data(), g2.data(), g1.size() * sizeof(double)));
    EXPECT_EQ(t1, t2);
}

}  // namespace
}  // namespace sdf

int main(int argc, char** argv) {
    const int devices = sdf::cuda::device_count();
    if (devices < 2) {
        std::printf("%d CUDA device(s) visible, this test needs 2: skipped\n", devices);
        return 77;
    }
    ::testing::InitGoogleTest(&argc, argv);
    return RUN_ALL_TESTS();
}
