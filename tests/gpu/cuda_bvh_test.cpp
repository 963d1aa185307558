// The CUDA BVH sampler against the CPU brute force on every BVH test mesh (the procedural
// shapes, the sliver sphere, the flat slab, bunny and dragon when present), CC and BCC
// lattices (both strategies), float and double, all three kernels; pieces; point queries.
// Same triangle: the same double evaluation (1e-12 relative); another triangle: a tie.
#include <gtest/gtest.h>

#include <random>

#include "core/lattice/lattice_fitting.h"
#include "harness/sampling/sampler_table.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"

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
                const SampledField cpu = make_sampler(options("cpu", "brute_force", precision))->sample(m.mesh, lattice);
                for (const char* kernel : {"brick", "seeded", "unseeded", "warp"})
                    for (BccStrategy s : {BccStrategy::TwoGrids, BccStrategy::DoubleResolution}) {
                        if (lattice.type == LatticeType::CC && s == BccStrategy::DoubleResolution) continue;
                        const SampledField gpu = make_sampler(options("cuda", "bvh", precision, kernel, s))->sample(m.mesh, lattice);
                        const std::string what = m.name + " " + lattice_notation(lattice) + " " + precision_name(precision) +
                                                 " " + kernel + " " + bcc_strategy_name(s);
                        test::FieldComparer cmp(m.mesh, test::epsilon_of(precision), 1e-12, 1e-13, 1e-8);
                        cmp.fields(cpu, gpu, what);
                        if (HasFatalFailure()) return;
                        print(what, cmp.agreement(), gpu);
                        EXPECT_EQ(gpu.sampler["method"], "bvh");
                    }
            }
        }
    }
}

TEST(CudaBvh, SlabsDoNotChangeTheResult) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[4].mesh;  // soccer ball
    const Lattice lattice = fit_lattice(LatticeType::BCC, {24, 25, 26}, mesh.bounds(), 0.1);
    SamplerOptions o = options("cuda", "bvh", Precision::Float);
    const SampledField whole = make_sampler(o)->sample(mesh, lattice);
    o.max_points_per_piece = 1000;  // a few z-layers per slab
    const SampledField split = make_sampler(o)->sample(mesh, lattice);
    EXPECT_GT(split.sampler["plan"]["pieces"].get<int>(), 2);
    EXPECT_EQ(whole.distance, split.distance);
    EXPECT_EQ(whole.closest_triangle, split.closest_triangle);
}

TEST(CudaBvh, PointQueriesEqualTheCpu) {
    for (const test::NamedMesh& m : test::bvh_test_meshes()) {
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<double> u(-0.75, 0.75);
        std::vector<Vec3d> pts(4001);
        for (auto& p : pts) p = m.mesh.bounds().center() + component_mul(m.mesh.bounds().extent(), Vec3d{u(rng), u(rng), u(rng)});
        for (Precision precision : {Precision::Float, Precision::Double}) {
            const auto cpu = make_sampler(options("cpu", "bvh", precision))->query(m.mesh, pts);
            const auto gpu = make_sampler(options("cuda", "bvh", precision))->query(m.mesh, pts);
            test::FieldComparer cmp(m.mesh, test::epsilon_of(precision), 1e-12, 1e-13, 1e-8);
            cmp.samples(pts, cpu, gpu, m.name + " points " + precision_name(precision));
            if (HasFatalFailure()) return;
        }
    }
}

TEST(CudaBvh, RepeatedCallsReuseTheUploadedBvh) {
    const PreparedMesh& mesh = test::bvh_test_meshes()[3].mesh;  // pawn
    const Lattice lattice = fit_lattice(LatticeType::CC, {16, 16, 16}, mesh.bounds(), 0.1);
    auto sampler = make_sampler(options("cuda", "bvh", Precision::Float));
    const SampledField first = sampler->sample(mesh, lattice);
    const SampledField second = sampler->sample(mesh, lattice);
    EXPECT_TRUE(first.sampler["bvh"]["uploaded_by_this_call"].get<bool>());
    EXPECT_FALSE(second.sampler["bvh"]["uploaded_by_this_call"].get<bool>());
    EXPECT_EQ(first.distance, second.distance);
}

TEST(CudaBvh, ErrorsNameTheKernel) {
    try {
        make_sampler(options("cuda", "bvh", Precision::Float, "tuned"));
        FAIL() << "a brute-force kernel name must be rejected by the BVH sampler";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("tuned"), std::string::npos);
    }
}

}  // namespace
}  // namespace sdf
