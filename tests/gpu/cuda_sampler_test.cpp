// Both CUDA kernels against the CPU reference, on every test mesh, CC and BCC (both
// strategies): max |dd| <= 1e-5 of the bounding-box diagonal, the same sign and triangle
// except at ties, gradients within 1e-4.
#include <gtest/gtest.h>

#include <cstring>

#include "core/sampling/adversarial_cases.h"

#include <random>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "harness/config/mesh_spec.h"
#include "harness/sampling/sampler_table.h"
#include "kernels/distance/closest_point_on_triangle.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

struct NamedMesh {
    std::string name;
    PreparedMesh mesh;
};

/// The procedural shapes always; the real meshes when the data path has them.
const std::vector<NamedMesh>& test_meshes() {
    static const std::vector<NamedMesh> meshes = [] {
        std::vector<NamedMesh> m;
        m.push_back({"sphere", prepare_mesh(make_icosphere(4))});
        m.push_back({"box", prepare_mesh(make_box({1, 0.5, 0.75}))});
        m.push_back({"torus", prepare_mesh(make_torus())});
        m.push_back({"pawn", prepare_mesh(make_pawn())});
        m.push_back({"soccer_ball", prepare_mesh(make_soccer_ball())});
        for (const char* file : {"bunny.obj", "dragon.obj"}) {
            try {
                m.push_back({file, prepare_mesh(load_mesh(mesh_spec_from_argument(file), data_search_path()))});
            } catch (const std::exception& e) {
                std::printf("note: %s not available (%s)\n", file, e.what());
            }
        }
        return m;
    }();
    return meshes;
}

/// Prepared-mesh index of each file-order triangle index.
std::vector<int> prepared_index(const PreparedMesh& m) {
    std::vector<int> inverse(size_t(m.report().input_triangles), -1);
    for (size_t i = 0; i < m.source_triangle().size(); ++i) inverse[size_t(m.source_triangle()[i])] = int(i);
    return inverse;
}

double distance_to(const PreparedMesh& m, const Vec3d& p, int prepared) {
    const Int3 t = m.triangles()[size_t(prepared)];
    return std::sqrt(closest_point_on_triangle(p, m.vertices()[size_t(t.x)], m.vertices()[size_t(t.y)],
                                               m.vertices()[size_t(t.z)]).distance_squared);
}

struct Agreement {
    double max_abs_distance = 0;
    int triangle_ties = 0, sign_ties = 0;
};

/// Compares a GPU field with the CPU reference point by point.
Agreement compare(const PreparedMesh& mesh, const SampledField& cpu, const SampledField& gpu, const std::string& what) {
    const double diag = mesh.bounds().diagonal(), tol = 1e-5 * diag;
    const std::vector<int> index = prepared_index(mesh);
    Agreement a;
    EXPECT_EQ(cpu.size(), gpu.size()) << what;
    for (int64_t i = 0; i < cpu.size(); ++i) {
        const double dc = cpu.distance[size_t(i)], dg = gpu.distance[size_t(i)];
        a.max_abs_distance = std::max(a.max_abs_distance, std::abs(dc - dg));
        EXPECT_LE(std::abs(dc - dg), tol) << what << " point " << i;
        const int tc = cpu.closest_triangle[size_t(i)], tg = gpu.closest_triangle[size_t(i)];
        bool tie = false;
        if (tc != tg) {
            // Allowed only when the GPU's triangle is exactly as near (a shared edge or vertex,
            // or a float near-tie).
            const Vec3d p = cpu.lattice.position(i);
            EXPECT_NEAR(distance_to(mesh, p, index[size_t(tg)]), distance_to(mesh, p, index[size_t(tc)]), tol)
                << what << " point " << i;
            tie = true;
            ++a.triangle_ties;
        }
        if ((dc < 0) != (dg < 0)) {
            ++a.sign_ties;
            EXPECT_TRUE(tie || std::abs(dc) <= tol) << what << " sign differs at point " << i << " d=" << dc;
        }
        if (!tie) {
            const double scale = std::max(std::abs(dc), 0.01 * diag);
            EXPECT_LE(length(cpu.gradient[size_t(i)] - gpu.gradient[size_t(i)]), 1e-4 * scale / std::max(std::abs(dc), 1e-30))
                << what << " point " << i;
        }
    }
    return a;
}

SampledField sample(const PreparedMesh& mesh, const Lattice& lattice, const std::string& backend, const std::string& kernel,
                    BccStrategy strategy = BccStrategy::TwoGrids, Precision precision = Precision::Float) {
    SamplerOptions o;
    o.backend = backend;
    o.method = "brute_force";
    o.kernel = kernel;
    o.bcc_strategy = strategy;
    o.precision = precision;
    o.progress = false;
    return make_sampler(o)->bind(share(mesh))->sample(lattice);
}

TEST(CudaSampler, BothKernelsAgreeWithTheCpuReferenceOnEveryMesh) {
    for (const NamedMesh& m : test_meshes()) {
        const bool big = m.mesh.triangles().size() > 50000;
        const Lattice cc = fit_lattice(LatticeType::CC, big ? Int3{32, 32, 32} : Int3{40, 36, 33}, m.mesh.bounds(), 0.1);
        const Lattice bcc = fit_lattice(LatticeType::BCC, big ? Int3{26, 26, 26} : Int3{31, 29, 27}, m.mesh.bounds(), 0.1);
        for (const Lattice& lattice : {cc, bcc}) {
            const SampledField cpu = sample(m.mesh, lattice, "cpu", "vectorized");
            for (const char* kernel : {"thesis", "tuned"})
                for (BccStrategy s : {BccStrategy::TwoGrids, BccStrategy::DoubleResolution}) {
                    if (lattice.type == LatticeType::CC && s == BccStrategy::DoubleResolution) continue;
                    const std::string what = m.name + " " + lattice_notation(lattice) + " " + kernel + " " + bcc_strategy_name(s);
                    const SampledField gpu = sample(m.mesh, lattice, "cuda", kernel, s);
                    const Agreement a = compare(m.mesh, cpu, gpu, what);
                    std::printf("%-44s max|dd| = %.3g (%.2g of diag), triangle ties %d, sign ties %d, %.3g pairs/s\n",
                                what.c_str(), a.max_abs_distance, a.max_abs_distance / m.mesh.bounds().diagonal(),
                                a.triangle_ties, a.sign_ties, gpu.timings.pairs_per_second());
                }
        }
    }
}

TEST(CudaSampler, DoublePrecisionMatchesTheCpuInDouble) {
    const PreparedMesh& mesh = test_meshes()[4].mesh;  // soccer ball
    const Lattice lattice = fit_lattice(LatticeType::BCC, {20, 21, 22}, mesh.bounds(), 0.1);
    const SampledField cpu = sample(mesh, lattice, "cpu", "", BccStrategy::TwoGrids, Precision::Double);
    for (const char* kernel : {"thesis", "tuned"}) {
        const SampledField gpu = sample(mesh, lattice, "cuda", kernel, BccStrategy::TwoGrids, Precision::Double);
        for (int64_t i = 0; i < cpu.size(); ++i)
            ASSERT_NEAR(gpu.distance[size_t(i)], cpu.distance[size_t(i)], 1e-12 * mesh.bounds().diagonal()) << kernel << " " << i;
    }
}

TEST(CudaSampler, SplittingLatticesAndMeshesDoesNotChangeTheResult) {
    const PreparedMesh& mesh = test_meshes()[4].mesh;
    const Lattice lattice = fit_lattice(LatticeType::BCC, {24, 24, 24}, mesh.bounds(), 0.1);
    for (const char* kernel : {"thesis", "tuned"}) {
        const SampledField whole = sample(mesh, lattice, "cuda", kernel);
        SamplerOptions o;
        o.backend = "cuda";
        o.method = "brute_force";
        o.kernel = kernel;
        o.progress = false;
        o.max_points_per_piece = 1000;       // many pieces (thesis: one 32^3 region per piece)
        o.max_triangles_per_chunk = 700;     // several triangle chunks per piece
        const SampledField split = make_sampler(o)->bind(share(mesh))->sample(lattice);
        EXPECT_GT(split.sampler.details.at("plan")["pieces"].get<int>(), 1) << kernel;
        EXPECT_GT(split.sampler.details.at("plan")["triangle_chunks"].get<int>(), 1) << kernel;
        EXPECT_EQ(whole.distance, split.distance) << kernel;
        EXPECT_EQ(whole.closest_triangle, split.closest_triangle) << kernel;
    }
}

TEST(CudaSampler, PointQueriesMatchTheCpu) {
    const PreparedMesh& mesh = test_meshes()[3].mesh;  // pawn
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-0.8, 0.8);
    std::vector<Vec3d> pts(5001);
    for (auto& p : pts) p = mesh.bounds().center() + Vec3d{u(rng), u(rng), u(rng)};
    SamplerOptions o;
    o.backend = "cpu";
    o.method = "brute_force";
    o.progress = false;
    const auto cpu = make_sampler(o)->bind(share(mesh))->query(pts);
    o.backend = "cuda";
    for (const char* kernel : {"thesis", "tuned"}) {
        o.kernel = kernel;
        const auto gpu = make_sampler(o)->bind(share(mesh))->query(pts);
        ASSERT_EQ(gpu.size(), pts.size());
        for (size_t i = 0; i < pts.size(); ++i)
            ASSERT_NEAR(gpu[i].distance, cpu[i].distance, 1e-5 * mesh.bounds().diagonal()) << kernel << " " << i;
    }
}

TEST(CudaSampler, ErrorsNameTheKernel) {
    SamplerOptions o;
    o.backend = "cuda";
    o.method = "brute_force";
    o.kernel = "fastest";
    try {
        make_sampler(o);
        FAIL() << "an unknown kernel must be rejected";
    } catch (const std::exception& e) {
        EXPECT_NE(std::string(e.what()).find("fastest"), std::string::npos);
    }
}


/// The certified float search (kernels/distance/search_certificate.h) on the GPU: on the
/// adversarial cases (core/sampling/adversarial_cases.h) every certified float kernel returns
/// bit for bit the distance, gradient and triangle of the CPU double brute force, for point
/// queries and for a lattice hugging the cube's top face 1e-4 above it.
TEST(CudaSampler, CertifiedFloatEqualsDoubleBruteForceOnAdversarialCases) {
    auto same = [](double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; };
    for (const AdversarialCase& c : adversarial_cases(2026, 1500)) {
        const PreparedMesh mesh = prepare_mesh(c.mesh);
        SamplerOptions ref;
        ref.backend = "cpu";
        ref.method = "brute_force";
        ref.precision = Precision::Double;
        ref.progress = false;
        const std::vector<PointSample> want = make_sampler(ref)->bind(share(mesh))->query(c.points);
        for (const char* kernel : {"tuned"}) {
            SamplerOptions o = ref;
            o.backend = "cuda";
            o.method = "brute_force";
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
        }
        if (c.mesh.name != "cube") continue;
        Lattice lattice;  // 40 x 40 x 3 points, the lowest layer 1e-4 above the top face
        lattice.type = LatticeType::CC;
        lattice.origin = {-0.5123, -0.5077, 0.5 + 1e-4};
        lattice.spacing = 1.0 / 37.0;
        lattice.resolution = {40, 40, 3};
        const SampledField want_field = make_sampler(ref)->bind(share(mesh))->sample(lattice);
        for (const char* kernel : {"tuned"}) {
            SamplerOptions o = ref;
            o.backend = "cuda";
            o.method = "brute_force";
            o.precision = Precision::Float;
            o.kernel = kernel;
            const SampledField got = make_sampler(o)->bind(share(mesh))->sample(lattice);
            ASSERT_EQ(got.distance.size(), want_field.distance.size());
            int64_t bad = 0;
            for (size_t i = 0; i < got.distance.size(); ++i)
                bad += !(got.closest_triangle[i] == want_field.closest_triangle[i] && same(got.distance[i], want_field.distance[i]));
            EXPECT_EQ(bad, 0) << "cube lattice " << kernel;
            EXPECT_EQ(got.sampler.search_certificate->certified, true) << kernel;
        }
    }
}

}  // namespace
}  // namespace sdf
