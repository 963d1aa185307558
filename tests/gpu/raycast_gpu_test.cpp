// The CUDA ray caster against the CPU one (both cast_pixel, both in float from the same
// float Hermite data): every interpolator, on the exact sphere and on a sampled pawn, CC and
// BCC. Stated tolerances (the two differ only in rounding: nvcc and g++ -march=native both
// contract multiply-adds into FMAs, but not in the same places):
//   - hit/miss differs in at most 0.05% of the pixels (a silhouette ray may graze a root
//     within the float rounding of the two evaluations);
//   - over pixels hit by both, 99.9% have |depth difference| <= 2e-3 lattice units (twice
//     the refinement tolerance: each root estimate lies within it of its own float root),
//     normal angle <= 0.05 degrees and |shade difference| <= 1e-3.
// Also prints the CUDA kernel time of a 1024^2 bcc_cubic render (median of 20 launches).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "../raycast/raycast_test_util.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/raycast/image_metrics.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "harness/render/render_backend.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

struct FieldCase {
    std::string name;
    SampledField cc, bcc;
    Bounds3 bounds;
};

const std::vector<FieldCase>& fields() {
    static const std::vector<FieldCase> cases = [] {
        std::vector<FieldCase> c;
        const test::Sphere sphere;
        c.push_back({"sphere", test::sphere_field(sphere, LatticeType::CC, {32, 32, 32}),
                     test::sphere_field(sphere, LatticeType::BCC, {26, 26, 26}), sphere.bounds()});
        const PreparedMesh pawn = prepare_mesh(make_pawn());
        SamplerOptions so;
        so.progress = false;
        auto sampler = make_cpu_brute_force_sampler(so);
        c.push_back({"pawn", sampler->bind(share(pawn))->sample(fit_lattice(LatticeType::CC, {40, 40, 40}, pawn.bounds(), 0.1)),
                     sampler->bind(share(pawn))->sample(fit_lattice(LatticeType::BCC, {32, 32, 32}, pawn.bounds(), 0.1)), pawn.bounds()});
        return c;
    }();
    return cases;
}

struct Spec {
    const char* interpolator;
    const char* derivatives;
};

const Spec kSpecs[] = {{"trilinear", "fd"},        {"catmull_rom", "fd"},        {"tricubic_lm", "true"},
                       {"tricubic_lm", "fd"},       {"cc_bspline3", "fd"},        {"bcc_linear", "fd"},
                       {"bcc_cubic", "true"},       {"bcc_cubic", "fd"},          {"bcc_cubic_c0", "true"},
                       {"bcc_box_linear", "fd"},    {"bcc_box_quintic", "fd"},    {"bcc_box_quintic_qi", "fd"},
                       {"bcc_box_quintic_approx", "fd"}};

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, size_t(q * double(v.size())))];
}

TEST(CudaRaycast, AgreesWithTheCpuPixelForPixel) {
    constexpr int kSize = 256;
    for (const FieldCase& f : fields()) {
        for (const Spec& s : kSpecs) {
            const bool bcc = std::string(s.interpolator).rfind("bcc", 0) == 0;
            const SampledField& field = bcc ? f.bcc : f.cc;
            const Reconstruction recon(field, s.interpolator, s.derivatives);
            const CameraSpec camera = resolve_view(named_view("three_quarter"), f.bounds, kSize, kSize);
            RenderOptions cpu, gpu;
            cpu.backend = "cpu";
            gpu.backend = "cuda";
            cpu.progress = false;
            const RenderedImage a = render_reconstruction(recon, camera, cpu);
            const RenderedImage b = render_reconstruction(recon, camera, gpu);
            const double unit = bcc ? 0.5 * field.lattice.spacing : field.lattice.spacing;
            int mismatch = 0;
            std::vector<double> depth, angle, shade;
            for (size_t i = 0; i < a.pixels.size(); ++i) {
                const PixelRecord &p = a.pixels[i], &q = b.pixels[i];
                if (p.is_hit() != q.is_hit()) {
                    ++mismatch;
                    continue;
                }
                if (!p.is_hit()) {
                    EXPECT_EQ(q.shade, p.shade);
                    continue;
                }
                depth.push_back(std::abs(double(p.depth) - double(q.depth)) / unit);
                angle.push_back(angle_degrees(p.normal, q.normal));
                shade.push_back(std::abs(double(p.shade) - double(q.shade)));
            }
            const std::string what = f.name + " " + recon.description();
            std::printf("%-36s hits %zu, hit/miss differs %d px, p99.9: depth %.2e units, normal %.4f deg, shade %.2e;"
                        " kernel %.3f ms\n",
                        what.c_str(), depth.size(), mismatch, quantile(depth, 0.999), quantile(angle, 0.999),
                        quantile(shade, 0.999), 1e3 * b.info["kernel_seconds"].get<double>());
            EXPECT_GT(depth.size(), size_t(kSize * kSize / 10)) << what;
            EXPECT_LE(mismatch, int(0.0005 * kSize * kSize)) << what;
            EXPECT_LE(quantile(depth, 0.999), 2e-3) << what;
            EXPECT_LE(quantile(angle, 0.999), 0.05) << what;
            EXPECT_LE(quantile(shade, 0.999), 1e-3) << what;
        }
    }
}

TEST(CudaRaycast, ReportsKernelTimesOfA1024SquaredBccCubicRender) {
    const FieldCase& pawn = fields()[1];
    const Reconstruction recon(pawn.bcc, "bcc_cubic", "true");
    RenderOptions gpu;
    gpu.backend = "cuda";
    gpu.repetitions = 20;
    const CameraSpec camera = resolve_view(named_view("three_quarter"), pawn.bounds, 1024, 1024);
    const RenderedImage image = render_reconstruction(recon, camera, gpu);
    ASSERT_EQ(image.info["kernel_seconds_all"].size(), 20u);
    EXPECT_GT(image.info["kernel_seconds"].get<double>(), 0.0);
    EXPECT_GT(image.hit_count(), 1024 * 1024 / 20);
    std::printf("pawn BCC 32x32x64 bcc_cubic/true 1024^2: kernel median %.3f ms, min %.3f ms; upload %.3f ms, "
                "download %.3f ms; %.1f steps/pixel\n",
                1e3 * image.info["kernel_seconds"].get<double>(), 1e3 * image.info["kernel_seconds_min"].get<double>(),
                1e3 * image.info["upload_seconds"].get<double>(), 1e3 * image.info["download_seconds"].get<double>(),
                image.info["march"]["mean_steps"].get<double>());
}

TEST(CudaRaycast, RejectsNoRepetitions) {
    const Reconstruction recon(fields()[0].cc, "catmull_rom", "fd");
    RenderOptions gpu;
    gpu.backend = "cuda";
    gpu.repetitions = 0;
    EXPECT_THROW(render_reconstruction(recon, resolve_view(named_view("front"), fields()[0].bounds, 8, 8), gpu),
                 std::invalid_argument);
}

}  // namespace
}  // namespace sdf
