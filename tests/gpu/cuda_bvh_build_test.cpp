// The BVH built on the GPU (cuda/bvh/device_bvh_build.h) against its host emulation
// (core/bvh/lbvh.h): nodes, moments, slots and packed constants bit for bit (PLOC's last
// iterations in one block or not); and the CUDA BVH sampler's fields and point queries on
// the device-built tree against the host-built (SAH) tree: triangle, distance and gradient
// bit for bit, the sign too (the pseudonormal's and the certified winding number's side are
// both tree-independent).
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "core/lattice/lattice_fitting.h"
#include "core/sampling/adversarial_cases.h"
#include "cuda/bvh/bvh_sampler.h"
#include "cuda/bvh/device_bvh_build.h"
#include "cuda/util/device_mesh.h"
#include "core/winding/winding_sign.h"
#include "harness/sampling/sampler_table.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

struct Case {
    std::string name;
    const PreparedMesh* mesh;
};

/// The BVH test meshes and the adversarial cases' meshes, prepared once.
const std::vector<Case>& cases() {
    static std::vector<PreparedMesh> adversarial = [] {
        std::vector<PreparedMesh> m;
        for (const AdversarialCase& c : adversarial_cases(7, 1)) m.push_back(prepare_mesh(c.mesh));
        return m;
    }();
    static const std::vector<Case> all = [] {
        std::vector<Case> c;
        for (const test::NamedMesh& m : test::bvh_test_meshes()) c.push_back({m.name, &m.mesh});
        for (size_t i = 0; i < adversarial.size(); ++i) c.push_back({"adversarial " + adversarial[i].name(), &adversarial[i]});
        return c;
    }();
    return all;
}

template <typename V, typename A>
void expect_bytes_equal(const std::vector<V, A>& a, const std::vector<V, A>& b, const std::string& what) {
    ASSERT_EQ(a.size(), b.size()) << what;
    EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(V))) << what << " differ";
}

TEST(CudaBvhBuild, DeviceBuildEqualsTheHostEmulationBitForBit) {
    for (const Case& c : cases()) {
        const PreparedMesh& mesh = *c.mesh;
        if (mesh.triangles().size() <= 4) continue;
        const cuda::DeviceMesh<double> dmesh(mesh.buffers<double>());
        // PLOC four times: its last iterations in one block from the default cluster count,
        // from 6144 (the dragon's tail then starts at 5,370 clusters: all six chunks a
        // thread), from 100 clusters, and never (a launch sequence per iteration): the same
        // bytes.
        for (const auto& [builder, tail] : {std::pair{GpuBvhBuilder::Ploc, GpuBvhBuildOptions{}.ploc_tail_clusters},
                                            std::pair{GpuBvhBuilder::Ploc, 6144}, std::pair{GpuBvhBuilder::Ploc, 100},
                                            std::pair{GpuBvhBuilder::Ploc, 0},
                                            std::pair{GpuBvhBuilder::Lbvh, 0}}) {
        GpuBvhBuildOptions o;
        o.builder = builder;
        o.ploc_tail_clusters = tail;
        const std::string what = c.name + " " + gpu_bvh_builder_name(builder) + " tail " + std::to_string(tail);
        const auto device = cuda::build_lbvh_on_device(mesh, dmesh.view().vertices, dmesh.view().triangles, o);
        ASSERT_TRUE(device) << what;
        const LbvhBuild d = device->download();
        const LbvhBuild h = build_lbvh(mesh, o);
        EXPECT_EQ(d.within_depth, h.within_depth) << what;
        expect_bytes_equal(d.bvh.nodes, h.bvh.nodes, what + " nodes");
        expect_bytes_equal(d.moments, h.moments, what + " moments");
        expect_bytes_equal(d.bvh.triangle_index, h.bvh.triangle_index, what + " slots");
        expect_bytes_equal(d.bvh.packed_float, h.bvh.packed_float, what + " packed float");
        expect_bytes_equal(d.bvh.packed_double, h.bvh.packed_double, what + " packed double");
        EXPECT_EQ(d.bvh.stats.nodes, h.bvh.stats.nodes) << what;
        EXPECT_EQ(d.bvh.stats.depth, h.bvh.stats.depth) << what;
        EXPECT_EQ(d.bvh.stats.leaves, h.bvh.stats.leaves) << what;
        EXPECT_EQ(d.bvh.stats.largest_leaf, h.bvh.stats.largest_leaf) << what;
        EXPECT_NEAR(d.bvh.stats.sah_cost, h.bvh.stats.sah_cost, 1e-9 * h.bvh.stats.sah_cost) << what;
        std::printf("%-32s %7zu triangles: device %s, %.3f ms on the device\n", what.c_str(), mesh.triangles().size(),
                    d.bvh.stats.to_json().dump().c_str(), 1e3 * device->device_seconds);
        }
    }
}

SamplerOptions gpu_options(BvhBuildSite site, Precision precision) {
    SamplerOptions o;
    o.backend = "cuda";
    o.method = "bvh";
    o.precision = precision;
    o.progress = false;
    o.bvh_build = site;
    return o;
}

/// Same triangle, same |distance| and gradient up to the side bit for bit, in float and in
/// double (both searches return the double brute force's triangle on any tree: docs/bvh.md,
/// "Build on the GPU"); the side equal too (pseudonormal or certified winding sign).
struct SideCount {
    int64_t points = 0, other_side = 0;
};

void compare(double dh, const Vec3d& gh, int th, double dd, const Vec3d& gd, int td, bool winding,
             SideCount& n, const std::string& what, size_t i) {
    ++n.points;
    ASSERT_EQ(th, td) << what << " point " << i;
    ASSERT_EQ(std::abs(dh), std::abs(dd)) << what << " point " << i;
    // The certified winding sign (docs/winding.md) is tree-independent like the pseudonormal
    // one: no point may take the other side on the other tree.
    const bool flipped = (dh < 0) != (dd < 0);
    if (flipped) {
        ++n.other_side;
        FAIL() << what << " point " << i << ": the " << (winding ? "certified winding" : "pseudonormal")
               << " sign differs between the trees";
    } else {
        ASSERT_EQ(dh, dd) << what << " point " << i;
        ASSERT_EQ(gh.x, gd.x) << what << " point " << i;
        ASSERT_EQ(gh.y, gd.y) << what << " point " << i;
        ASSERT_EQ(gh.z, gd.z) << what << " point " << i;
    }
}

std::vector<Vec3d> query_points(const PreparedMesh& mesh, size_t count) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-0.75, 0.75);
    std::normal_distribution<double> g(0.0, 0.01 * mesh.bounds().diagonal());
    std::vector<Vec3d> pts(count);
    for (size_t i = 0; i < pts.size(); ++i) {
        if (i % 2 == 0) {
            pts[i] = mesh.bounds().center() + component_mul(mesh.bounds().extent(), Vec3d{u(rng), u(rng), u(rng)});
        } else {
            const Vec3d& v = mesh.vertices()[size_t(rng() % mesh.vertices().size())];
            pts[i] = v + Vec3d{g(rng), g(rng), g(rng)};
        }
    }
    return pts;
}

/// The needle fans (bvh_test_meshes.h), 1e7 from the origin and near it, points on the
/// surface among them (a computed Q below 0, exact ties at the apex): every CUDA BVH kernel,
/// float and double, on the host and the device tree, gives the CPU double brute force's
/// triangle, distance and gradient bit for bit (the pseudonormal sign on both sides).
TEST(CudaBvhBuild, NeedleFansEqualTheDoubleBruteForceOnEitherTree) {
    auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
    for (const Vec3d center : {Vec3d{1e7, -3e6, 5e6}, Vec3d{0.5, 0.25, -0.125}}) {
        const test::NeedleFan fan = test::make_needle_fan(center);
        const PreparedMesh mesh = test::prepare_needle_fan(fan);
        SamplerOptions ref;
        ref.backend = "cpu";
        ref.method = "brute_force";
        ref.precision = Precision::Double;
        ref.sign = SignMode::Pseudonormal;
        ref.progress = false;
        const std::vector<PointSample> want = make_sampler(ref)->bind(share(mesh))->query(fan.points);
        for (BvhBuildSite site : {BvhBuildSite::Host, BvhBuildSite::Device})
            for (Precision precision : {Precision::Float, Precision::Double})
                for (const auto& [kernel, id] : cuda::kCudaBvhKernels) {
                    SamplerOptions o = gpu_options(site, precision);
                    o.sign = SignMode::Pseudonormal;
                    o.kernel = kernel;
                    const std::vector<PointSample> got = make_sampler(o)->bind(share(mesh))->query(fan.points);
                    const std::string what = std::string(bvh_build_site_name(site)) + " " +
                                             (precision == Precision::Float ? "float " : "double ") + kernel;
                    int64_t bad = 0;
                    for (size_t i = 0; i < got.size(); ++i)
                        bad += !(got[i].triangle == want[i].triangle && same(got[i].distance, want[i].distance) &&
                                 same(got[i].gradient.x, want[i].gradient.x) && same(got[i].gradient.y, want[i].gradient.y) &&
                                 same(got[i].gradient.z, want[i].gradient.z));
                    EXPECT_EQ(bad, 0) << "needle fan at " << center.x << ": " << what;
                }
    }
}

TEST(CudaBvhBuild, FieldsAndQueriesOnTheDeviceTreeEqualTheHostTree) {
    for (const Case& c : cases()) {
        const PreparedMesh& mesh = *c.mesh;
        if (mesh.triangles().size() <= 4) continue;
        const bool winding = choose_sign_mode(mesh.report(), SignMode::Auto).mode == SignMode::Winding;
        for (Precision precision : {Precision::Float, Precision::Double}) {
            const int r = mesh.triangles().size() > 20000 ? 40 : 28;
            const Lattice cc = fit_lattice(LatticeType::CC, {r, r + 1, r + 2}, mesh.bounds(), 0.1);
            const Lattice bcc = fit_lattice(LatticeType::BCC, {r - 3, r - 2, r - 1}, mesh.bounds(), 0.1);
            auto host = make_sampler(gpu_options(BvhBuildSite::Host, precision));
            auto device = make_sampler(gpu_options(BvhBuildSite::Device, precision));
            SideCount n;
            for (const Lattice& lattice : {cc, bcc}) {
                const SampledField fh = host->bind(share(mesh))->sample(lattice), fd = device->bind(share(mesh))->sample(lattice);
                EXPECT_EQ(fh.sampler.details["bvh"]["built_on"], "host") << c.name;
                EXPECT_EQ(fd.sampler.details["bvh"]["built_on"], "device") << c.name;
                const std::string what = c.name + " " + lattice_notation(lattice) + " " + precision_name(precision);
                ASSERT_EQ(fh.size(), fd.size()) << what;
                for (int64_t i = 0; i < fh.size(); ++i) {
                    const size_t k = size_t(i);
                    compare(fh.distance[k], fh.gradient[k], fh.closest_triangle[k], fd.distance[k], fd.gradient[k],
                            fd.closest_triangle[k], winding, n, what, k);
                    if (HasFatalFailure()) return;
                }
            }
            const std::vector<Vec3d> pts = query_points(mesh, 4001);
            const auto qh = host->bind(share(mesh))->query(pts), qd = device->bind(share(mesh))->query(pts);
            for (size_t i = 0; i < pts.size(); ++i) {
                compare(qh[i].distance, qh[i].gradient, qh[i].triangle, qd[i].distance, qd[i].gradient, qd[i].triangle,
                        winding, n, c.name + " points " + precision_name(precision), i);
                if (HasFatalFailure()) return;
            }
            std::printf("%-28s %-6s sign %-12s %lld points, %lld on the other side\n",
                        c.name.c_str(), precision_name(precision), winding ? "winding" : "pseudonormal",
                        (long long)n.points, (long long)n.other_side);
        }
    }
}

/// The peers_gpu mesh (holes: the winding sign) on its 128^3 lattice: how many points
/// take the other side on the device tree (printed; everything else bit for bit).
TEST(CudaBvhBuild, WindingSidesOnTheLegacyDragon) {
    const std::string path = test::find_data_file("dragon-legacy.obj");
    if (path.empty()) GTEST_SKIP() << "dragon-legacy.obj not in SDF_DATA_PATH";
    const PreparedMesh mesh = prepare_mesh(load_obj(path));
    const bool winding = choose_sign_mode(mesh.report(), SignMode::Auto).mode == SignMode::Winding;
    const Lattice lattice = fit_lattice(LatticeType::CC, {128, 128, 128}, mesh.bounds(), 0.1);
    const SampledField fh = make_sampler(gpu_options(BvhBuildSite::Host, Precision::Float))->bind(share(mesh))->sample(lattice);
    const SampledField fd = make_sampler(gpu_options(BvhBuildSite::Device, Precision::Float))->bind(share(mesh))->sample(lattice);
    SideCount n;
    for (int64_t i = 0; i < fh.size(); ++i) {
        const size_t k = size_t(i);
        compare(fh.distance[k], fh.gradient[k], fh.closest_triangle[k], fd.distance[k], fd.gradient[k], fd.closest_triangle[k],
                winding, n, "dragon-legacy 128^3", k);
        if (HasFatalFailure()) return;
    }
    std::printf("dragon-legacy 128^3 float, sign %s: %lld points, %lld on the other side; build host %.4f s, device %.4f s "
                "(device %s)\n",
                winding ? "winding" : "pseudonormal", (long long)n.points, (long long)n.other_side,
                fh.sampler.details["bvh"]["build_seconds"].get<double>(), fd.sampler.details["bvh"]["build_seconds"].get<double>(),
                fd.sampler.details["bvh"].dump().c_str());
}

TEST(CudaBvhBuild, AutoBuildsOnTheDeviceForEverySign) {
    const PreparedMesh& solid = test::bvh_test_meshes()[3].mesh;  // pawn: pseudonormal
    const PreparedMesh bowl = test::open_bowl();                   // open: winding
    const Lattice l1 = fit_lattice(LatticeType::CC, {12, 12, 12}, solid.bounds(), 0.1);
    const Lattice l2 = fit_lattice(LatticeType::CC, {12, 12, 12}, bowl.bounds(), 0.1);
    const SampledField a = make_sampler(gpu_options(BvhBuildSite::Auto, Precision::Float))->bind(share(solid))->sample(l1);
    EXPECT_EQ(a.sampler.details["bvh"]["built_on"], "device");
    const SampledField a2 = make_sampler(gpu_options(BvhBuildSite::Auto, Precision::Double))->bind(share(solid))->sample(l1);
    EXPECT_EQ(a2.sampler.details["bvh"]["built_on"], "device");  // the double search is tree-independent too
    // The certified winding sign does not depend on the tree either (issue 37): auto builds the
    // open bowl's tree and moments on the device too.
    const SampledField b = make_sampler(gpu_options(BvhBuildSite::Auto, Precision::Float))->bind(share(bowl))->sample(l2);
    EXPECT_EQ(b.sampler.details["bvh"]["built_on"], "device");
    EXPECT_FALSE(b.sampler.details["bvh"].contains("device_build_skipped"));
    EXPECT_EQ(b.sampler.details["sign"]["winding"]["moments_built_on"], "device");
    const SampledField c = make_sampler(gpu_options(BvhBuildSite::Device, Precision::Float))->bind(share(bowl))->sample(l2);
    EXPECT_EQ(c.sampler.details["bvh"]["built_on"], "device");
    EXPECT_EQ(c.sampler.details["sign"]["winding"]["moments_built_on"], "device");
    // The binding builds the device tree; repeated calls search it.
    const auto bound = make_sampler(gpu_options(BvhBuildSite::Device, Precision::Float))->bind(share(solid));
    const SampledField first = bound->sample(l1), second = bound->sample(l1);
    EXPECT_TRUE(first.sampler.details["bvh"]["built_by_bind"].get<bool>());
    EXPECT_EQ(first.sampler.details["bvh"], second.sampler.details["bvh"]);
    EXPECT_EQ(first.distance, second.distance);
}

}  // namespace
}  // namespace sdf
