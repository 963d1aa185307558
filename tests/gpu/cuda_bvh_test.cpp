// The CUDA BVH sampler against the CPU brute force on every BVH test mesh (the procedural
// shapes, the sliver sphere, the flat slab, bunny and dragon when present), CC and BCC
// lattices (both strategies), float and double, every kernel; pieces; point queries (sorted
// into Morton order on the device); the narrow band (every kernel: the full field banded,
// bit for bit; "candidates" skips whole bricks). Same triangle: the same double evaluation
// (1e-12 relative); another triangle: a tie.
#include <gtest/gtest.h>

#include <cstring>
#include <new>

#include "core/sampling/adversarial_cases.h"

#include <random>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "cuda/bvh/bvh_sampler.h"
#include "harness/sampling/sampler_table.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

SamplerOptions options(const std::string& backend, const std::string& method, Precision precision,
                       const std::string& kernel = "", BccStrategy strategy = BccStrategy::TwoGrids) {
    SamplerOptions o;
    o.backend = backend;
    o.method = method;
    o.precision = precision;
    o.kernel = kernel;
    o.bcc_strategy = strategy;
    o.progress = false;
    return o;
}

void print(const std::string& what, const test::Agreement& a, const SampledField& f) {
    std::printf("%-52s max|dd| = %.3g, triangle ties %lld, sign ties %lld, %.3g queries/s\n", what.c_str(),
                a.max_abs_distance, (long long)a.triangle_ties, (long long)a.sign_ties,
                f.timings.kernel > 0 ? double(f.size()) / f.timings.kernel : 0.0);
}

TEST(CudaBvh, EqualsCpuBruteForceOnEveryMeshBothPrecisions) {
    for (const test::NamedMesh& m : test::bvh_test_meshes()) {
        const bool big = m.mesh.triangles().size() > 20000;
        for (Precision precision : {Precision::Float, Precision::Double}) {
            const int r = big ? (precision == Precision::Double ? 12 : 20) : 28;
            const Lattice cc = fit_lattice(LatticeType::CC, {r, r + 1, r + 2}, m.mesh.bounds(), 0.1);
            const Lattice bcc = fit_lattice(LatticeType::BCC, {r - 3, r - 2, r - 1}, m.mesh.bounds(), 0.1);
            for (const Lattice& lattice : {cc, bcc}) {
                const SampledField cpu = make_sampler(options("cpu", "brute_force", precision))->bind(share(m.mesh))->sample(lattice);
                for (const auto& [kernel, id] : cuda::kCudaBvhKernels)
                    for (BccStrategy s : {BccStrategy::TwoGrids, BccStrategy::DoubleResolution}) {
                        if (lattice.type == LatticeType::CC && s == BccStrategy::DoubleResolution) continue;
                        const SampledField gpu = make_sampler(options("cuda", "bvh", precision, kernel, s))->bind(share(m.mesh))->sample(lattice);
                        const std::string what = m.name + " " + lattice_notation(lattice) + " " + precision_name(precision) +
                                                 " " + kernel + " " + bcc_strategy_name(s);
                        test::FieldComparer cmp(m.mesh, test::epsilon_of(precision), 1e-12, 1e-13, 1e-8);
                        cmp.fields(cpu, gpu, what);
                        if (HasFatalFailure()) return;
                        print(what, cmp.agreement(), gpu);
                        EXPECT_EQ(gpu.sampler.method, "bvh");
                    }
            }
        }
    }
}

TEST(CudaBvh, SlabsDoNotChangeTheResult) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[4].mesh;  // soccer ball
    const Lattice lattice = fit_lattice(LatticeType::BCC, {24, 25, 26}, mesh.bounds(), 0.1);
    SamplerOptions o = options("cuda", "bvh", Precision::Float);
    const SampledField whole = make_sampler(o)->bind(share(mesh))->sample(lattice);
    o.max_points_per_piece = 1000;  // a few z-layers per slab
    const SampledField split = make_sampler(o)->bind(share(mesh))->sample(lattice);
    EXPECT_GT(split.sampler.details.at("plan")["pieces"].get<int>(), 2);
    EXPECT_EQ(whole.distance, split.distance);
    EXPECT_EQ(whole.closest_triangle, split.closest_triangle);
}

TEST(CudaBvh, PointQueriesEqualTheCpu) {
    for (const test::NamedMesh& m : test::bvh_test_meshes()) {
        // Uniform in the box, then Gaussian around vertices (as training-data generators
        // draw near the surface): 4001 points, not a multiple of a packet.
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<double> u(-0.75, 0.75);
        std::normal_distribution<double> g(0.0, 0.01 * m.mesh.bounds().diagonal());
        std::vector<Vec3d> pts(4001);
        for (size_t i = 0; i < pts.size(); ++i) {
            if (i % 2 == 0) {
                pts[i] = m.mesh.bounds().center() + component_mul(m.mesh.bounds().extent(), Vec3d{u(rng), u(rng), u(rng)});
            } else {
                const Vec3d& v = m.mesh.vertices()[size_t(rng() % m.mesh.vertices().size())];
                pts[i] = v + Vec3d{g(rng), g(rng), g(rng)};
            }
        }
        for (Precision precision : {Precision::Float, Precision::Double}) {
            const auto cpu = make_sampler(options("cpu", "bvh", precision))->bind(share(m.mesh))->query(pts);
            for (const char* kernel : {"warp", "candidates"}) {
                const auto gpu = make_sampler(options("cuda", "bvh", precision, kernel))->bind(share(m.mesh))->query(pts);
                test::FieldComparer cmp(m.mesh, test::epsilon_of(precision), 1e-12, 1e-13, 1e-8);
                cmp.samples(pts, cpu, gpu, m.name + " points " + precision_name(precision) + " " + kernel);
                if (HasFatalFailure()) return;
            }
        }
    }
}

/// The narrow band applied to a full field (SamplerOptions::band_width's definition).
SampledField banded(SampledField f, double w) {
    for (int64_t i = 0; i < f.size(); ++i)
        if (std::abs(f.distance[size_t(i)]) > w) {
            f.distance[size_t(i)] = f.distance[size_t(i)] < 0 ? -w : w;
            f.gradient[size_t(i)] = Vec3d(0.0);
            f.closest_triangle[size_t(i)] = kOutsideBandTriangle;
        }
    return f;
}


TEST(CudaBvh, NarrowBandIsTheFullFieldBandedBitForBit) {
    const auto& meshes = test::bvh_test_meshes();
    const std::vector<test::NamedMesh> cases = {meshes[2], meshes[4], {"open bowl", test::open_bowl()}};  // torus, soccer ball
    for (size_t which = 0; which < cases.size(); ++which) {
        const PreparedMesh& mesh = cases[which].mesh;
        const bool solid = which < 2;
        for (SignMode sign : {SignMode::Pseudonormal, SignMode::Winding})
            for (Precision precision : {Precision::Float, Precision::Double}) {
                const Lattice cc = fit_lattice(LatticeType::CC, {40, 41, 42}, mesh.bounds(), 0.3);
                const Lattice bcc = fit_lattice(LatticeType::BCC, {30, 31, 32}, mesh.bounds(), 0.3);
                // The two that skip bricks outside the band, one that searches everything
                // (the band applied by finalize_samples), and the brute force.
                const std::pair<const char*, const char*> samplers[] = {
                    {"bvh", "warp"}, {"bvh", "candidates"}, {"bvh", "unseeded"}, {"brute_force", ""}};
                for (const Lattice& lattice : {cc, bcc})
                    for (const auto& [method, kernel] : samplers) {
                        SamplerOptions o = options("cuda", method, precision, kernel);
                        o.sign = sign;
                        const SampledField full = make_sampler(o)->bind(share(mesh))->sample(lattice);
                        for (double fraction : {0.02, 0.1}) {
                            const double w = fraction * mesh.bounds().diagonal();
                            o.band_width = w;
                            const SampledField band = make_sampler(o)->bind(share(mesh))->sample(lattice);
                            const SampledField expected = banded(full, w);
                            const std::string what = cases[which].name + " " + lattice_notation(lattice) + " " + method + "/" + kernel + " " +
                                                     precision_name(precision) + (sign == SignMode::Winding ? " winding" : "") +
                                                     " band " + std::to_string(fraction);
                            ASSERT_EQ(band.distance, expected.distance) << what;
                            ASSERT_EQ(band.closest_triangle, expected.closest_triangle) << what;
                            for (int64_t i = 0; i < band.size(); ++i)
                                ASSERT_TRUE(band.gradient[size_t(i)] == expected.gradient[size_t(i)]) << what << " point " << i;
                            EXPECT_EQ(band.sampler.details.at("band_width").get<double>(), w);
                            int64_t in_band = 0;
                            for (int32_t t : band.closest_triangle) in_band += t != kOutsideBandTriangle;
                            EXPECT_GT(in_band, 0) << what;
                            EXPECT_LT(in_band, band.size()) << what;
                            if (std::string(kernel) == "candidates") {
                                const auto& c = band.sampler.details.at("candidates");
                                std::printf("%-60s bricks searched %lld, outside the band %lld\n", what.c_str(),
                                            (long long)c["bricks_searched"].get<int64_t>(),
                                            (long long)c["bricks_outside_band"].get<int64_t>());
                                // Skipped where the sign allows it: winding (per point) or a solid.
                                if (fraction < 0.05 && (solid || sign == SignMode::Winding)) {
                                    EXPECT_GT(c["bricks_outside_band"].get<int64_t>(), 0) << what;
                                }
                                if (!solid && sign == SignMode::Pseudonormal) {
                                    EXPECT_EQ(c["bricks_outside_band"].get<int64_t>(), 0) << what;
                                }
                            }
                        }
                    }
            }
    }
}

// Issue 38's sliver (an angle of 0.5 degrees, inradius 0.54) under a band of 0.05: a brick's
// centre whose search ranks the sliver by its edges over-estimates its distance by up to the
// inradius, which the brick skip must allow for (FloatSearchBound::sliver_reach_*), or bricks
// on the sliver come out "outside the band". Every banded CUDA field equals the CPU double
// brute force's field banded, to the bit.
TEST(CudaBvh, NarrowBandNearASliverKeepsItsBricks) {
    const PreparedMesh mesh = prepare_mesh(test::make_issue38_slivers());
    Lattice lattice;
    lattice.type = LatticeType::CC;
    lattice.origin = {40.0, -0.4, -0.3};
    lattice.spacing = 0.05;
    lattice.resolution = {400, 17, 13};
    const double w = lattice.spacing;
    SamplerOptions cpu;
    cpu.backend = "cpu";
    cpu.method = "brute_force";
    cpu.precision = Precision::Double;
    cpu.sign = SignMode::Winding;
    cpu.progress = false;
    const SampledField expected = banded(make_sampler(cpu)->bind(share(mesh))->sample(lattice), w);
    for (const char* kernel : {"warp", "candidates"})
        for (Precision precision : {Precision::Float, Precision::Double}) {
            SamplerOptions o = cpu;
            o.backend = "cuda";
            o.method = "bvh";
            o.kernel = kernel;
            o.precision = precision;
            o.band_width = w;
            const SampledField band = make_sampler(o)->bind(share(mesh))->sample(lattice);
            const std::string what = std::string("sliver ") + kernel + " " + precision_name(precision);
            ASSERT_EQ(band.closest_triangle, expected.closest_triangle) << what;
            ASSERT_EQ(band.distance, expected.distance) << what;
        }
}

TEST(CudaBvh, RepeatedCallsOfABoundSamplerEqualEachOther) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[3].mesh;  // pawn
    const Lattice lattice = fit_lattice(LatticeType::CC, {16, 16, 16}, mesh.bounds(), 0.1);
    const auto bound = make_sampler(options("cuda", "bvh", Precision::Float))->bind(share(mesh));  // the upload
    const SampledField first = bound->sample(lattice);
    const SampledField second = bound->sample(lattice);
    EXPECT_EQ(first.sampler.details.at("bvh"), second.sampler.details.at("bvh"));
    EXPECT_EQ(first.distance, second.distance);
    EXPECT_EQ(first.closest_triangle, second.closest_triangle);
}

/// A binding's device copies are of its mesh's own tree (PreparedMesh::bvh(), or the device
/// build's): a second binding of one mesh builds no host tree, and a mesh made at a freed
/// mesh's address from the same input (same name, hash, triangle count and bounds), but
/// flipped outward, gets its own tree, upload, winding sign and certifier: its fields equal
/// a fresh sampler's bit for bit.
TEST(CudaBvh, AMeshAtAFreedMeshsAddressGetsItsOwnUpload) {
    TriangleMesh inward = make_icosphere(2);
    for (Int3& t : inward.triangles) std::swap(t.y, t.z);
    MeshPreparationOptions keep_inward, flip;
    keep_inward.detect_intersections = flip.detect_intersections = false;
    keep_inward.orient_outward = false;
    const PreparedMesh fresh = prepare_mesh(inward, flip);
    const Lattice lattice = fit_lattice(LatticeType::CC, {12, 12, 12}, fresh.bounds(), 0.2);
    for (const char* method : {"bvh", "brute_force"})
        for (SignMode sign : {SignMode::Winding, SignMode::Pseudonormal}) {
            SCOPED_TRACE(std::string(method) + " " + sign_mode_name(sign));
            SamplerOptions o = options("cuda", method, Precision::Float);
            o.sign = sign;
            const SampledField expected = make_sampler(o)->bind(share(fresh))->sample(lattice);
            auto sampler = make_sampler(o);
            alignas(PreparedMesh) unsigned char storage[sizeof(PreparedMesh)];
            PreparedMesh* first = new (storage) PreparedMesh(prepare_mesh(inward, keep_inward));
            sampler->bind(share(first))->sample(lattice);
            first->~PreparedMesh();
            PreparedMesh* second = new (storage) PreparedMesh(prepare_mesh(inward, flip));
            ASSERT_EQ(static_cast<void*>(second), static_cast<void*>(first));
            const SampledField got = sampler->bind(share(second))->sample(lattice);
            EXPECT_EQ(got.distance, expected.distance);
            EXPECT_EQ(got.closest_triangle, expected.closest_triangle);
            if (std::string(method) == "bvh") {
                EXPECT_TRUE(got.sampler.details.at("bvh")["built_by_bind"].get<bool>());
                // Another sampler of the same mesh shares its host tree (a tree built on the
                // device, bvh_build auto with the pseudonormal sign, is each sampler's own).
                const SampledField other = make_sampler(o)->bind(share(second))->sample(lattice);
                const nlohmann::json& tree = other.sampler.details.at("bvh");
                EXPECT_EQ(tree.at("built_by_bind").get<bool>(), tree.value("built_on", "host") == "device");
                EXPECT_EQ(other.distance, expected.distance);
            }
            second->~PreparedMesh();
        }
}

TEST(CudaBvh, ErrorsNameTheKernel) {
    try {
        make_sampler(options("cuda", "bvh", Precision::Float, "tuned"));
        FAIL() << "a brute-force kernel name must be rejected by the BVH sampler";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("tuned"), std::string::npos);
    }
}


/// The certified float search (kernels/distance/search_certificate.h) on the GPU: on the
/// adversarial cases (core/sampling/adversarial_cases.h) every certified float kernel returns
/// bit for bit the distance, gradient and triangle of the CPU double brute force, for point
/// queries and for a lattice hugging the cube's top face 1e-4 above it.
TEST(CudaBvh, CertifiedFloatEqualsDoubleBruteForceOnAdversarialCases) {
    auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
    for (const AdversarialCase& c : adversarial_cases(2026, 1500)) {
        const PreparedMesh mesh = prepare_mesh(c.mesh);
        SamplerOptions ref;
        ref.backend = "cpu";
        ref.method = "brute_force";
        ref.precision = Precision::Double;
        ref.progress = false;
        const std::vector<PointSample> want = make_sampler(ref)->bind(share(mesh))->query(c.points);
        for (const auto& [kernel, id] : cuda::kCudaBvhKernels) {
            SamplerOptions o = ref;
            o.backend = "cuda";
            o.method = "bvh";
            o.precision = Precision::Float;
            o.kernel = kernel;
            auto sampler = make_sampler(o);
            SamplingTimings timings;
            const std::vector<PointSample> got = sampler->bind(share(mesh))->query(c.points, &timings);
            int64_t bad = 0;
            for (size_t i = 0; i < got.size(); ++i)
                bad += !(got[i].triangle == want[i].triangle && same(got[i].distance, want[i].distance) &&
                         same(got[i].gradient.x, want[i].gradient.x) && same(got[i].gradient.y, want[i].gradient.y) &&
                         same(got[i].gradient.z, want[i].gradient.z));
            std::printf("%-32s %-10s re-ranked %lld of %lld, full double %lld\n", c.mesh.name.c_str(), kernel,
                        (long long)timings.reranked_points,
                        (long long)timings.certified_points,
                        (long long)timings.full_double_points);
            EXPECT_EQ(bad, 0) << c.mesh.name << " " << kernel;
            EXPECT_EQ(timings.certified_points, int64_t(c.points.size())) << c.mesh.name << " " << kernel;
            // warp fuses the certificate (kernels/bvh/streamed_certificate.h), listing each
            // point's candidates: only a list that outgrows kNearListSlots (a fan of exact ties)
            // takes the separate pass's search, which re-ranks too.
            EXPECT_LE(timings.full_double_points, timings.reranked_points) << c.mesh.name << " " << kernel;
        }
        if (c.mesh.name != "cube" && c.mesh.name != "fan_plate") continue;
        Lattice lattice;
        lattice.type = LatticeType::CC;
        if (c.mesh.name == "cube") {  // 40 x 40 x 3 points, the lowest layer 1e-4 above the top face
            lattice.origin = {-0.5123, -0.5077, 0.5 + 1e-4};
            lattice.spacing = 1.0 / 37.0;
            lattice.resolution = {40, 40, 3};
        } else {  // the plate's box: points over its fan centres, whose dozens of exact ties
                  // overflow the warp kernel's two deferred candidates
            lattice.origin = {-1.1, -1.1, -0.2};
            lattice.spacing = 2.2 / 22.0;
            lattice.resolution = {23, 23, 5};
        }
        const SampledField want_field = make_sampler(ref)->bind(share(mesh))->sample(lattice);
        for (const auto& [kernel, id] : cuda::kCudaBvhKernels) {
            SamplerOptions o = ref;
            o.backend = "cuda";
            o.method = "bvh";
            o.precision = Precision::Float;
            o.kernel = kernel;
            const SampledField got = make_sampler(o)->bind(share(mesh))->sample(lattice);
            ASSERT_EQ(got.distance.size(), want_field.distance.size());
            int64_t bad = 0;
            for (size_t i = 0; i < got.distance.size(); ++i)
                bad += !(got.closest_triangle[i] == want_field.closest_triangle[i] && same(got.distance[i], want_field.distance[i]));
            EXPECT_EQ(bad, 0) << c.mesh.name << " lattice " << kernel;
            EXPECT_EQ(got.sampler.search_certificate->certified, true) << kernel;
        }
    }
}

}  // namespace
}  // namespace sdf
