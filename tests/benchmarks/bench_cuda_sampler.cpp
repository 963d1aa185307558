// Google Benchmark of the CUDA brute-force kernels, timed with CUDA events (manual time =
// the sampler's kernel time; transfers excluded). Counters: point-triangle pairs per second.
//   SDF_DATA_PATH=... bench_cuda_sampler --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <cstdio>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "harness/config/mesh_spec.h"
#include "harness/sampling/sampler_table.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

struct Case {
    std::string name;
    std::shared_ptr<PreparedMesh> mesh;
    Lattice lattice;
};

void run(benchmark::State& state, const Case& c, const std::string& kernel, int points_per_thread) {
    SamplerOptions o;
    o.backend = "cuda";
    o.method = "brute_force";
    o.kernel = kernel;
    o.points_per_thread = points_per_thread;
    o.progress = false;
    const auto sampler = make_sampler(o)->bind(share(c.mesh));  // the uploads
    sampler->sample(c.lattice);  // warm-up
    double pairs = 0;
    for (auto _ : state) {
        const SampledField f = sampler->sample(c.lattice);
        state.SetIterationTime(f.timings.kernel);
        pairs = f.timings.point_triangle_pairs;
    }
    state.counters["pairs/s"] = benchmark::Counter(pairs * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["points"] = double(c.lattice.num_points());
    state.counters["triangles"] = double(c.mesh->triangles().size());
}

std::vector<Case> cases() {
    std::vector<Case> out;
    auto add = [&](const std::string& label, std::shared_ptr<PreparedMesh> m, LatticeType t, int64_t samples) {
        const int r = cubic_resolution_for_samples(t, samples);
        const Lattice l = fit_lattice(t, {r, r, r}, m->bounds(), 0.1);
        out.push_back({label + "/" + lattice_notation(l) + (t == LatticeType::CC ? "cc" : "bcc"), m, l});
    };
    auto load = [](const std::string& file) -> std::shared_ptr<PreparedMesh> {
        try {
            return std::make_shared<PreparedMesh>(prepare_mesh(load_mesh(mesh_spec_from_argument(file), data_search_path())));
        } catch (const std::exception& e) {
            std::fprintf(stderr, "skipping %s: %s\n", file.c_str(), e.what());
            return nullptr;
        }
    };
    const auto soccer = std::make_shared<PreparedMesh>(prepare_mesh(make_soccer_ball()));
    add("soccer_ball", soccer, LatticeType::CC, 262144);
    add("soccer_ball", soccer, LatticeType::CC, 2097152);
    if (auto bunny = load("bunny.obj")) {
        add("bunny", bunny, LatticeType::CC, 32768);
        add("bunny", bunny, LatticeType::CC, 262144);
    }
    if (auto dragon = load("dragon-legacy.obj")) {
        add("dragon_legacy", dragon, LatticeType::CC, 32768);
        add("dragon_legacy", dragon, LatticeType::CC, 262144);
        add("dragon_legacy", dragon, LatticeType::BCC, 262144);
    }
    return out;
}

}  // namespace
}  // namespace sdf

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (!sdf::cuda_backend_available()) {
        std::printf("no CUDA device: nothing to benchmark\n");
        return 0;
    }
    static const std::vector<sdf::Case> all = sdf::cases();
    for (const sdf::Case& c : all) {
        for (const char* kernel : {"thesis", "tuned"})
            benchmark::RegisterBenchmark((std::string(kernel) + "/" + c.name).c_str(),
                                         [&c, kernel](benchmark::State& s) { sdf::run(s, c, kernel, 0); })
                ->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(0.5);
        if (c.name.rfind("dragon_legacy/64x64x64", 0) == 0)
            for (int k : {1, 2, 4, 8})
                benchmark::RegisterBenchmark(("tuned_k" + std::to_string(k) + "/" + c.name).c_str(),
                                             [&c, k](benchmark::State& s) { sdf::run(s, c, "tuned", k); })
                    ->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(0.5);
    }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
