// Several devices in one process (harness/sampling/multi_device_sampler.h) and the devices
// of MPI ranks (harness/sampling/device_selection.h), checked on the CPU: the "devices"
// option's codec and its errors, the rank -> device mapping, the slab and point splits,
// and the multi-device sampler over CPU samplers standing in for GPUs, whose fields, point
// queries and host queries equal one sampler's byte for byte (tests/gpu/multi_gpu_test.cpp
// does the same with real GPUs).
#include <gtest/gtest.h>

#include <cstring>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/sampling/point_sets.h"
#include "harness/config/sampler_spec.h"
#include "harness/sampling/device_selection.h"
#include "harness/sampling/multi_device_sampler.h"
#include "harness/sampling/sampler_table.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

using nlohmann::json;

SamplerOptions read(const json& j) { return sampler_options_from_json(j, "test.json"); }

std::string error_of(const json& j) {
    try {
        read(j);
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

TEST(DevicesOption, ReadsAllListsAndTheCommandLinesText) {
    EXPECT_TRUE(read(json::object()).devices.is_default());
    EXPECT_TRUE(read({{"devices", json::array()}}).devices.is_default());
    EXPECT_TRUE(read({{"devices", "all"}}).devices.all);
    EXPECT_EQ(read({{"devices", {0, 1}}}).devices.list, (std::vector<int>{0, 1}));
    EXPECT_EQ(read({{"devices", {3, 1}}}).devices.list, (std::vector<int>{3, 1}));
    EXPECT_EQ(read({{"devices", "0,1"}}).devices.list, (std::vector<int>{0, 1}));
    EXPECT_EQ(read({{"devices", "[2, 0]"}}).devices.list, (std::vector<int>{2, 0}));
    // Written and read back the same (the MPI wire, the manifest).
    for (const json& v : {json("all"), json({1, 2}), json::array()}) {
        const SamplerOptions o = read({{"devices", v}});
        EXPECT_EQ(read(sampler_options_to_json(o)).devices, o.devices) << v;
        EXPECT_EQ(sampler_options_to_json(o).at("devices"), v);
    }
}

TEST(DevicesOption, BadValuesNameTheKeyAndWhatWasExpected) {
    for (const json& bad : {json(-1), json(1), json(1.5), json(true), json("al"), json("0,,1"), json("x"), json({0, 0}),
                            json({-1}), json({0.5}), json({"a"}), json::object()}) {
        const std::string e = error_of({{"devices", bad}});
        EXPECT_NE(e.find("sampler.devices"), std::string::npos) << bad << ": " << e;
        EXPECT_NE(e.find("\"all\" or a list of distinct CUDA device ordinals"), std::string::npos) << bad << ": " << e;
    }
    EXPECT_NE(error_of({{"devices", {0, 0}}}).find("device 0 is listed twice"), std::string::npos);
}

TEST(DeviceSelection, ResolvesAgainstTheVisibleDevices) {
    SamplerOptions o;
    EXPECT_EQ(resolve_devices(o, 2), (std::vector<int>{0}));
    o.device = 1;
    EXPECT_EQ(resolve_devices(o, 2), (std::vector<int>{1}));
    o.device = 2;
    EXPECT_THROW(resolve_devices(o, 2), std::invalid_argument);
    o.device = 0;
    o.devices.all = true;
    EXPECT_EQ(resolve_devices(o, 4), (std::vector<int>{0, 1, 2, 3}));
    EXPECT_EQ(resolve_devices(o, 1), (std::vector<int>{0}));  // Slurm's --gpus-per-task=1
    EXPECT_THROW(resolve_devices(o, 0), std::invalid_argument);
    o.devices = DeviceSelection{false, {1, 0}};
    EXPECT_EQ(resolve_devices(o, 2), (std::vector<int>{1, 0}));
    try {
        resolve_devices(o, 1);
        ADD_FAILURE() << "device 1 of 1 accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("sampler.devices: device 1 is not visible: 1 CUDA device is visible"),
                  std::string::npos)
            << e.what();
    }
}

/// The devices of local rank r of n ranks on a host with `visible` GPUs.
std::vector<int> devices_of(SamplerOptions o, int r, int n, int visible) {
    o.backend = "cuda";
    const SamplerOptions placed = place_rank_on_devices(o, r, n, visible);
    return placed.devices.is_default() ? std::vector<int>{placed.device} : placed.devices.list;
}

TEST(DeviceSelection, RanksTakeTheGpusOfTheirHostByLocalRank) {
    const SamplerOptions one;  // the default: one GPU per rank
    for (int r = 0; r < 4; ++r) EXPECT_EQ(devices_of(one, r, 4, 4), (std::vector<int>{r})) << r;
    for (int r = 0; r < 4; ++r) EXPECT_EQ(devices_of(one, r, 4, 2), (std::vector<int>{r % 2})) << r;  // shared
    for (int r = 0; r < 2; ++r) EXPECT_EQ(devices_of(one, r, 2, 1), (std::vector<int>{0})) << r;  // one visible each
    SamplerOptions all;
    all.devices.all = true;  // a rank may drive several GPUs
    EXPECT_EQ(devices_of(all, 0, 2, 4), (std::vector<int>{0, 2}));
    EXPECT_EQ(devices_of(all, 1, 2, 4), (std::vector<int>{1, 3}));
    EXPECT_EQ(devices_of(all, 0, 1, 4), (std::vector<int>{0, 1, 2, 3}));
    EXPECT_EQ(devices_of(all, 2, 3, 2), (std::vector<int>{0}));  // more ranks than GPUs: shared
    SamplerOptions listed;
    listed.devices.list = {3, 1};
    EXPECT_EQ(devices_of(listed, 0, 2, 4), (std::vector<int>{3}));
    EXPECT_EQ(devices_of(listed, 1, 2, 4), (std::vector<int>{1}));
    // Other backends and hosts without GPUs: unchanged.
    SamplerOptions cpu = all;
    cpu.backend = "cpu";
    EXPECT_TRUE(place_rank_on_devices(cpu, 1, 2, 4).devices.all);
    all.backend = "cuda";
    EXPECT_TRUE(place_rank_on_devices(all, 1, 2, 0).devices.all);
}

TEST(DeviceSplit, SmallJobsAreNotSplitAndSayWhy) {
    // The measured losing case (docs/distributed.md): 4,194,304 query points on 2 H200s.
    DeviceSplit d = plan_device_split(4194304, -1, 2, kDefaultMinPointsPerDevice);
    EXPECT_EQ(d.used, 1);
    EXPECT_FALSE(d.split());
    EXPECT_EQ(d.why, "2 devices requested, 1 used: 4194304 points, fewer than 2 x 8388608 (min_points_per_device: the "
                     "fewest points a device is given)");
    json j = d.to_json();
    EXPECT_EQ(j.at("count"), 2);
    EXPECT_EQ(j.at("used"), 1);
    EXPECT_EQ(j.at("split"), false);
    EXPECT_EQ(j.at("min_points_per_device"), kDefaultMinPointsPerDevice);
    EXPECT_EQ(j.at("why_not"), d.why);
    EXPECT_FALSE(j.contains("why_fewer"));
    // The measured paying case: CC 512^3 (512 z-planes) on 2 devices, and on 4.
    EXPECT_EQ(plan_device_split(int64_t(512) * 512 * 512, 512, 2, kDefaultMinPointsPerDevice).used, 2);
    EXPECT_EQ(plan_device_split(int64_t(512) * 512 * 512, 512, 4, kDefaultMinPointsPerDevice).used, 4);
    // The threshold exactly: 2 x M points split in two, one fewer does not.
    EXPECT_EQ(plan_device_split(2 * kDefaultMinPointsPerDevice, -1, 2, kDefaultMinPointsPerDevice).used, 2);
    EXPECT_EQ(plan_device_split(2 * kDefaultMinPointsPerDevice - 1, -1, 2, kDefaultMinPointsPerDevice).used, 1);
    // Fewer devices than requested: as many as get M points each, and the report says why.
    d = plan_device_split(3 * kDefaultMinPointsPerDevice, -1, 4, kDefaultMinPointsPerDevice);
    EXPECT_EQ(d.used, 3);
    EXPECT_EQ(d.why, "4 devices requested, 3 used: 25165824 points, 8388608 or more a device (min_points_per_device)");
    j = d.to_json();
    EXPECT_EQ(j.at("why_fewer"), d.why);
    EXPECT_FALSE(j.contains("why_not"));
    // A lattice's planes: one z-plane is not split; two planes go to at most two devices.
    d = plan_device_split(1000, 1, 2, 1);
    EXPECT_EQ(d.used, 1);
    EXPECT_EQ(d.why, "2 devices requested, 1 used: 1 z-plane, one or more a device");
    EXPECT_EQ(plan_device_split(1000, 2, 4, 1).used, 2);
    // One device: nothing to say. A threshold of 0 or 1 splits whatever can be (tests).
    d = plan_device_split(int64_t(1) << 30, 7, 1, kDefaultMinPointsPerDevice);
    EXPECT_EQ(d.used, 1);
    EXPECT_TRUE(d.why.empty());
    EXPECT_EQ(plan_device_split(2, -1, 2, 0).used, 2);
    EXPECT_EQ(plan_device_split(3, -1, 4, 1).used, 3);
}

TEST(DeviceSplit, TheThresholdIsATypedOptionWithItsDefault) {
    EXPECT_EQ(SamplerOptions{}.min_points_per_device, int64_t(1) << 23);
    EXPECT_EQ(read(json::object()).min_points_per_device, kDefaultMinPointsPerDevice);
    EXPECT_EQ(read({{"min_points_per_device", 1}}).min_points_per_device, 1);
    EXPECT_EQ(sampler_options_to_json(read({{"min_points_per_device", 4096}})).at("min_points_per_device"), 4096);
    const std::string e = error_of({{"min_points_per_device", -1}});
    EXPECT_NE(e.find("sampler.min_points_per_device"), std::string::npos) << e;
}

TEST(DeviceSplit, PiecesTileThePointsAndSlabsTheirSlab) {
    for (int64_t n : {0, 1, 7, 100, 1001})
        for (int parts : {1, 2, 3, 8}) {
            const std::vector<PointRange> r = split_points(n, parts);
            int64_t next = 0;
            for (const PointRange& p : r) {
                EXPECT_EQ(p.begin, next);
                EXPECT_GE(p.count, n > 0 ? 1 : 0);
                next += p.count;
            }
            EXPECT_EQ(next, n) << n << " " << parts;
        }
    const Lattice bcc = fit_lattice(LatticeType::BCC, {5, 6, 9}, Bounds3{{-1, -1, -1}, {1, 1, 1}}, 0.1);
    const std::vector<double> cost = {1, 5, 5, 1, 1, 1, 9, 1, 1};
    for (const LatticeSlab slab : {LatticeSlab{0, 9}, LatticeSlab{2, 7}, LatticeSlab{8, 9}})
        for (int parts : {1, 2, 3, 4, 12}) {
            const std::vector<LatticeSlab> subs = split_slab(cost, slab, parts);
            EXPECT_EQ(int(subs.size()), std::min(parts, slab.z_end - slab.z_begin));
            std::vector<int> seen(size_t(slab_point_count(bcc, slab)), 0);
            int next = slab.z_begin;
            for (const LatticeSlab& s : subs) {
                EXPECT_EQ(s.z_begin, next);
                EXPECT_GT(s.z_end, s.z_begin);
                next = s.z_end;
                for (int p = 0; p < 2; ++p) {
                    const StorageRange r = sub_slab_storage(bcc, slab, s, p);
                    EXPECT_EQ(r.count, slab_storage(bcc, s, p).count);
                    for (int64_t i = r.offset; i < r.offset + r.count; ++i) ++seen[size_t(i)];
                }
            }
            EXPECT_EQ(next, slab.z_end);
            for (int c : seen) ASSERT_EQ(c, 1) << "slab " << slab.z_begin << ".." << slab.z_end << ", " << parts << " parts";
        }
}

// ---- the multi-device sampler over CPU samplers standing in for devices -----------------------

SamplerOptions cpu_bvh() {
    SamplerOptions o;
    o.backend = "cpu";
    o.method = "bvh";
    o.threads = 1;
    o.progress = false;
    o.min_points_per_device = 64;  // small lattices split (the default would run them on one device)
    return o;
}

SamplerOptions cpu_bvh_default_threshold() {
    SamplerOptions o = cpu_bvh();
    o.min_points_per_device = SamplerOptions{}.min_points_per_device;
    return o;
}

std::unique_ptr<Sampler> fake_devices(const SamplerOptions& o, std::vector<int> devices, std::vector<int>* made = nullptr) {
    return make_multi_device_sampler(
        o, std::move(devices),
        [made](const SamplerOptions& one) {
            EXPECT_TRUE(one.devices.is_default());
            if (made) made->push_back(one.device);
            return make_sampler(one);
        },
        [](int d) { return json{{"index", d}, {"name", "fake " + std::to_string(d)}}; });
}

void expect_same_bytes(const SampledField& a, const SampledField& b, const std::string& what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    const size_t n = size_t(a.size());
    EXPECT_EQ(0, std::memcmp(a.distance.data(), b.distance.data(), n * sizeof(double))) << what;
    EXPECT_EQ(0, std::memcmp(a.gradient.data(), b.gradient.data(), n * sizeof(Vec3d))) << what;
    EXPECT_EQ(0, std::memcmp(a.closest_triangle.data(), b.closest_triangle.data(), n * sizeof(int32_t))) << what;
}

/// Every member byte for byte (PointSample has padding, so not one memcmp of the arrays).
void expect_same_samples(const std::vector<PointSample>& a, const std::vector<PointSample>& b, const std::string& what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    for (size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(0, std::memcmp(&a[i].distance, &b[i].distance, sizeof(double))) << what << " point " << i;
        ASSERT_EQ(0, std::memcmp(&a[i].gradient, &b[i].gradient, sizeof(Vec3d))) << what << " point " << i;
        ASSERT_EQ(a[i].triangle, b[i].triangle) << what << " point " << i;
    }
}

TEST(MultiDeviceSampler, FieldsEqualOneDevicesByteForByte) {
    const auto mesh = share(prepare_mesh(make_torus(1.0, 0.35, 24, 12)));
    for (const LatticeType type : {LatticeType::CC, LatticeType::BCC})
        for (const double band : {0.0, 0.05}) {
            SamplerOptions o = cpu_bvh();
            o.band_width = band;
            const Lattice lattice = fit_lattice(type, {13, 11, 17}, mesh->bounds(), 0.1);
            const SampledField one = make_sampler(o)->bind(mesh)->sample(lattice);
            for (int devices : {2, 3, 5}) {
                std::vector<int> ids;
                for (int d = 0; d < devices; ++d) ids.push_back(d);
                std::vector<int> made;
                const auto bound = fake_devices(o, ids, &made)->bind(mesh);
                EXPECT_EQ(made, ids);
                const std::string what = std::string(lattice_type_name(type)) + " band " + std::to_string(band) + ", " +
                                         std::to_string(devices) + " devices";
                const SampledField many = bound->sample(lattice);
                expect_same_bytes(one, many, what);
                // The BVH's brick skip depends on where a slab cuts the bricks (as for MPI
                // ranks, docs/distributed.md): with a band only the band's counts must agree.
                if (band == 0) {
                    EXPECT_EQ(many.sampler.points_computed, one.sampler.points_computed) << what;
                }
                if (one.sampler.band) {
                    ASSERT_TRUE(many.sampler.band) << what;
                    EXPECT_EQ(many.sampler.band->points_in_band, one.sampler.band->points_in_band) << what;
                    EXPECT_EQ(many.sampler.band->points_outside, one.sampler.band->points_outside) << what;
                }
                const json& d = many.sampler.details.at("devices");
                EXPECT_TRUE(d.at("split").get<bool>()) << what;
                EXPECT_EQ(d.at("used"), devices) << what;
                EXPECT_EQ(d.at("min_points_per_device"), 64) << what;
                ASSERT_EQ(d.at("parts").size(), size_t(devices)) << what;
                int next = 0;
                for (size_t i = 0; i < d.at("parts").size(); ++i) {
                    const json& p = d.at("parts")[i];
                    EXPECT_EQ(p.at("device").at("index"), int(i));
                    EXPECT_EQ(p.at("z_planes")[0].get<int>(), next);
                    next = p.at("z_planes")[1].get<int>();
                }
                EXPECT_EQ(next, lattice.resolution.z);
                // A slab of the lattice (an MPI rank's, sdf-sample's) is split the same way.
                const LatticeSlab slab{3, 12};
                expect_same_bytes(make_sampler(o)->bind(mesh)->sample_slab(lattice, slab), bound->sample_slab(lattice, slab),
                                  what + ", slab 3..12");
            }
        }
}

TEST(MultiDeviceSampler, ASmallJobRunsOnTheFirstDeviceAndSaysWhy) {
    const auto mesh = share(prepare_mesh(make_torus(1.0, 0.35, 24, 12)));
    const Lattice lattice = fit_lattice(LatticeType::CC, {4, 4, 3}, mesh->bounds(), 0.1);  // 48 points < 2 x 64
    const SampledField one = make_sampler(cpu_bvh())->bind(mesh)->sample(lattice);
    const SampledField many = fake_devices(cpu_bvh(), {1, 0})->bind(mesh)->sample(lattice);
    expect_same_bytes(one, many, "small");
    const json& d = many.sampler.details.at("devices");
    EXPECT_FALSE(d.at("split").get<bool>());
    EXPECT_EQ(d.at("used"), 1);
    EXPECT_EQ(d.at("why_not"), "2 devices requested, 1 used: 48 points, fewer than 2 x 64 (min_points_per_device: the "
                               "fewest points a device is given)")
        << d;
    EXPECT_EQ(d.at("parts")[0].at("device").at("index"), 1);
}

TEST(MultiDeviceSampler, AJobSplitsOverAsManyDevicesAsItsThresholdAllows) {
    const auto mesh = share(prepare_mesh(make_torus(1.0, 0.35, 24, 12)));
    const Lattice lattice = fit_lattice(LatticeType::CC, {13, 11, 17}, mesh->bounds(), 0.1);  // 2431 points
    SamplerOptions o = cpu_bvh();
    o.min_points_per_device = 1000;  // two devices' worth
    const SampledField one = make_sampler(o)->bind(mesh)->sample(lattice);
    const SampledField many = fake_devices(o, {0, 1, 2, 3, 4})->bind(mesh)->sample(lattice);
    expect_same_bytes(one, many, "threshold 1000");
    const json& d = many.sampler.details.at("devices");
    EXPECT_TRUE(d.at("split").get<bool>());
    EXPECT_EQ(d.at("count"), 5);
    EXPECT_EQ(d.at("used"), 2);
    EXPECT_EQ(d.at("parts").size(), 2u);
    EXPECT_EQ(d.at("why_fewer"), "5 devices requested, 2 used: 2431 points, 1000 or more a device (min_points_per_device)");
    // The default threshold keeps this lattice, and a point list, on the first device.
    const SampledField unsplit = fake_devices(cpu_bvh_default_threshold(), {0, 1})->bind(mesh)->sample(lattice);
    expect_same_bytes(one, unsplit, "default threshold");
    EXPECT_FALSE(unsplit.sampler.details.at("devices").at("split").get<bool>());
    EXPECT_EQ(unsplit.sampler.details.at("devices").at("min_points_per_device"), kDefaultMinPointsPerDevice);
}

TEST(MultiDeviceSampler, PointQueriesEqualOneDevicesByteForByte) {
    const auto mesh = share(prepare_mesh(make_torus(1.0, 0.35, 24, 12)));
    const std::vector<Vec3d> points = make_point_set(*mesh, PointSetSpec{PointSetKind::GaussianSurface, 1001, 0.05, 0.1, 7});
    const std::vector<PointSample> one = make_sampler(cpu_bvh())->bind(mesh)->query(points);
    for (int devices : {2, 3}) {
        std::vector<int> ids;
        for (int d = 0; d < devices; ++d) ids.push_back(d);
        const auto bound = fake_devices(cpu_bvh(), ids)->bind(mesh);
        SamplingTimings t;
        const std::vector<PointSample> many = bound->query(points, &t);
        expect_same_samples(one, many, std::to_string(devices) + " devices");
        // Host arrays in and out: float32 rows with a stride of 4 (an N x 4 array's columns).
        std::vector<float> xyzw(4 * points.size());
        for (size_t i = 0; i < points.size(); ++i)
            for (int c = 0; c < 3; ++c) xyzw[4 * i + size_t(c)] = float(points[i][c]);
        const HostPoints host{xyzw.data(), true, int64_t(points.size()), 4, 1};
        std::vector<double> d1(points.size()), dn(points.size()), g1(3 * points.size()), gn(3 * points.size());
        std::vector<int32_t> t1(points.size()), tn(points.size());
        make_sampler(cpu_bvh())->bind(mesh)->query_host(host, {d1.data(), g1.data(), t1.data()});
        bound->query_host(host, {dn.data(), gn.data(), tn.data()});
        EXPECT_EQ(0, std::memcmp(d1.data(), dn.data(), d1.size() * sizeof(double)));
        EXPECT_EQ(0, std::memcmp(g1.data(), gn.data(), g1.size() * sizeof(double)));
        EXPECT_EQ(t1, tn);
    }
}

TEST(MultiDeviceSampler, TheCpuBackendRefusesAListOfGpus) {
    SamplerOptions o = cpu_bvh();
    o.devices.list = {0, 1};
    try {
        make_sampler(o);
        ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("sampler.devices: a list of CUDA devices needs the backend cuda"), std::string::npos)
            << e.what();
    }
    o.devices = DeviceSelection{true, {}};  // "all" GPUs of a machine that samples on its CPU: its threads
    EXPECT_NO_THROW(make_sampler(o));
}

}  // namespace
}  // namespace sdf
