// Every filter of the interpolator table (each derivative source but fd_weighted) rendered by
// the ray caster: the GPU's evaluation speed of each filter, and the CPU's for comparison.
// One field per lattice: the procedural pawn sampled (CPU BVH) on CC 64^3 and BCC 51x51x102
// (262,144 vs 257,651 points), the camera "three_quarter" at 512x512. The ray caster
// evaluates the reconstruction (value + gradient, float) at every march step of every pixel.
//   /cuda: manual time = the median CUDA-event time of one launch over 10 launches after a
//          warm-up (cuda/raycast/raycast.h); skipped without the CUDA backend or a GPU.
//   /cpu:  wall time of one render on all cores (float, as the GPU).
// Counters: "evals" = march steps summed over the pixels (the evaluations while stepping;
// the root refinement adds a few per hit pixel), "evals/s" = evals / time, "hits".
//   bench_raycast_filters --benchmark_counters_tabular=true [--benchmark_filter=/cuda]
#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/raycast/views.h"
#include "harness/render/render_backend.h"
#include "harness/sampling/sampler_table.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

constexpr int kImageSize = 512;

const PreparedMesh& pawn() {
    static const PreparedMesh mesh = prepare_mesh(make_pawn());
    return mesh;
}

const SampledField& field_for(LatticeType type) {
    static const auto sample = [](LatticeType t, Int3 resolution) {
        SamplerOptions o;
        o.backend = "cpu";
        o.method = "bvh";
        o.progress = false;
        return sample_once(*make_sampler(o), share(pawn()), fit_lattice(t, resolution, pawn().bounds(), 0.1));
    };
    static const SampledField cc = sample(LatticeType::CC, {64, 64, 64});
    static const SampledField bcc = sample(LatticeType::BCC, {51, 51, 51});
    return type == LatticeType::CC ? cc : bcc;
}

void render(benchmark::State& state, ReconstructionSpec spec, const std::string& backend) {
    if (backend == "cuda" && !cuda_render_available()) {
        state.SkipWithError("no CUDA backend in this build or no GPU");
        return;
    }
    spec.threads = 0;
    const Reconstruction recon(field_for(interpolator_lattice(spec.interpolator)), spec);
    const CameraSpec camera = resolve_view(named_view("three_quarter"), pawn().bounds(), kImageSize, kImageSize);
    RenderOptions options;
    options.backend = backend;
    options.progress = false;
    options.precision = Precision::Float;
    options.repetitions = backend == "cuda" ? 10 : 1;
    double evals = 0, hits = 0;
    for (auto _ : state) {
        const RenderedImage image = render_reconstruction(recon, camera, options);
        state.SetIterationTime(backend == "cuda" ? image.info.at("kernel_seconds").get<double>()
                                                 : image.info.at("seconds").get<double>());
        evals = 0;
        for (const PixelRecord& p : image.pixels) evals += p.steps;
        hits = double(image.hit_count());
    }
    state.counters["evals"] = evals;
    state.counters["evals/s"] = benchmark::Counter(evals * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["hits"] = hits;
}

void register_all() {
    for (const std::string& name : interpolator_names()) {
        const InterpolatorKind kind = parse_interpolator(name);
        for (DerivativeSource source : valid_derivative_sources(kind)) {
            if (source == DerivativeSource::FiniteDifferencesWeighted) continue;
            const ReconstructionSpec spec{kind, source};
            for (const char* backend : {"cuda", "cpu"})
                benchmark::RegisterBenchmark(("BM_Raycast/" + name + "/" + derivative_source_name(source) + "/" + backend).c_str(),
                                             render, spec, std::string(backend))
                    ->UseManualTime()
                    ->Unit(benchmark::kMillisecond)
                    ->Iterations(backend == std::string("cuda") ? 5 : 1);
        }
    }
}

}  // namespace
}  // namespace sdf

int main(int argc, char** argv) {
    sdf::register_all();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
