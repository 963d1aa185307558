// Google Benchmark of the narrow band (issue 14) and of streamed sampling on the CPU: the BVH
// sampler's brick kernel on the dragon's CC lattices with no band and with bands of 1 and 4
// spacings (bricks a probe proves outside the band are not searched), and sdf-sample's slab
// streaming of the same lattice to a scratch file (sampling overlapped with the writes).
//   SDF_DATA_PATH=... bench_narrow_band --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_obj.h"
#include "core/parallel/parallel_for.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "harness/build_config.h"
#include "harness/sampling/streamed_sampling.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

/// dragon.obj from SDF_DATA_PATH or the build's default data directories; null when absent.
const PreparedMesh* dragon() {
    static const std::unique_ptr<PreparedMesh> mesh = []() -> std::unique_ptr<PreparedMesh> {
        std::string dirs = std::getenv("SDF_DATA_PATH") ? std::getenv("SDF_DATA_PATH") : "";
        dirs += std::string(":") + SDF_DATA_DIR_DEFAULT;
        for (char& c : dirs) if (c == ';') c = ':';
        std::stringstream ss(dirs);
        for (std::string d; std::getline(ss, d, ':');)
            if (!d.empty() && std::ifstream(d + "/dragon.obj").good())
                return std::make_unique<PreparedMesh>(prepare_mesh(load_obj(d + "/dragon.obj")));
        return nullptr;
    }();
    return mesh.get();
}

/// The CC cube of r^3 points around the mesh (10% margin), and the CPU BVH's options.
Lattice cube_lattice(const PreparedMesh& mesh, int r) { return fit_lattice(LatticeType::CC, {r, r, r}, mesh.bounds(), 0.1); }

SamplerOptions cpu_bvh_options() {
    SamplerOptions o;
    o.backend = "cpu";
    o.method = "bvh";
    o.progress = false;
    return o;
}

/// Args: resolution, band in spacings (0: none).
void BM_CpuBvhBand(benchmark::State& state) {
    const PreparedMesh* mesh = dragon();
    if (!mesh) { state.SkipWithError("dragon.obj not found: set SDF_DATA_PATH"); return; }
    const Lattice lattice = cube_lattice(*mesh, int(state.range(0)));
    SamplerOptions o = cpu_bvh_options();
    o.band_width = double(state.range(1)) * lattice.spacing;
    const auto sampler = make_cpu_bvh_sampler(o)->bind(share(mesh));  // the BVH (if not built yet) and sign data
    SampledField f = sampler->sample(lattice);
    for (auto _ : state) {
        f = sampler->sample(lattice);
        state.SetIterationTime(f.timings.kernel);
    }
    const double points = double(lattice.num_points());
    state.counters["points/s"] = benchmark::Counter(points * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["computed"] = double(f.sampler.points_computed) / points;
    if (f.sampler.band.has_value()) {
        state.counters["in_band"] = double(f.sampler.band->points_in_band) / points;
        state.counters["probes"] = double(f.sampler.band->probes) / points;
    }
    state.counters["threads"] = double(resolve_thread_count(0));
}

/// Args: resolution, memory budget in MiB. End-to-end time of the streamed write (float32
/// distance and gradient) into the system's temporary folder.
void BM_StreamedSampling(benchmark::State& state) {
    const PreparedMesh* mesh = dragon();
    if (!mesh) { state.SkipWithError("dragon.obj not found: set SDF_DATA_PATH"); return; }
    const Lattice lattice = cube_lattice(*mesh, int(state.range(0)));
    const SamplerOptions o = cpu_bvh_options();
    const auto sampler = make_cpu_bvh_sampler(o)->bind(share(mesh));
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "bench_narrow_band_stream";
    std::filesystem::create_directories(dir);
    StreamOptions s;
    s.header_path = (dir / "field.json").string();
    s.write.closest_triangle = false;
    s.write.overwrite = Overwrite::Allow;
    s.fixed_bytes = estimate_fixed_bytes(*mesh);
    s.memory_budget = s.fixed_bytes + uint64_t(state.range(1)) * (1u << 20);
    s.progress = false;
    StreamResult result;
    for (auto _ : state) {
        result = sample_streamed(*sampler, o, lattice, s, {});
        state.SetIterationTime(result.seconds);
    }
    std::filesystem::remove_all(dir);
    state.counters["slabs"] = result.plan.slabs;
    state.counters["bytes/s"] = benchmark::Counter(double(result.plan.output_bytes) * double(state.iterations()),
                                                   benchmark::Counter::kIsRate);
    state.counters["peak_rss_MiB"] = double(result.peak_resident_bytes) / (1 << 20);
}

BENCHMARK(BM_CpuBvhBand)->Args({128, 0})->Args({128, 1})->Args({128, 4})->ArgNames({"res", "band_h"})->UseManualTime()
    ->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);
BENCHMARK(BM_StreamedSampling)->Args({128, 64})->Args({128, 1024})->ArgNames({"res", "budget_MiB"})->UseManualTime()
    ->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3)->ReportAggregatesOnly(true);

}  // namespace
}  // namespace sdf

BENCHMARK_MAIN();
