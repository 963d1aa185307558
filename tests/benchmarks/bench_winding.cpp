// Google Benchmark of the winding-number sign on the CC lattice of a mesh (default the
// dragon; 64^3 = 262k and 128^3 = 2,097k points), side by side with the unsigned work it adds to:
//   UnsignedBvh   the CPU BVH sampler (seeded kernel: nearest triangle + pseudonormal sign)
//   WindingFast   Barill et al.'s fast winding number at beta (x10 in the name) and order
//   WindingCertified  the same, with every sign certified against the rigorous bound
//   WindingExact  the exact sum over every triangle (on the first 512 lattice points)
// Args: resolution, threads (0 = all)[, beta x 10, order]. Times are per call; compare
// "points/s" across rows (the exact row runs far fewer points).
//   SDF_DATA_PATH=... bench_winding --benchmark_counters_tabular=true [--benchmark_filter=...]
//   SDF_BENCH_MESH=bunny.obj selects another mesh.
#include <benchmark/benchmark.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "cpu_reference/bvh/bvh_cpu.h"
#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_mesh.h"
#include "core/parallel/parallel_for.h"
#include "core/winding/winding_sign.h"
#include "harness/build_config.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

std::string mesh_file() { return std::getenv("SDF_BENCH_MESH") ? std::getenv("SDF_BENCH_MESH") : "dragon.obj"; }

std::shared_ptr<PreparedMesh> load(const std::string& file) {
    static std::map<std::string, std::shared_ptr<PreparedMesh>> cache;
    if (cache.count(file)) return cache[file];
    std::string dirs = std::getenv("SDF_DATA_PATH") ? std::getenv("SDF_DATA_PATH") : "";
    dirs += std::string(":") + SDF_DATA_DIR_DEFAULT;
    for (char& c : dirs) if (c == ';') c = ':';
    std::stringstream ss(dirs);
    for (std::string d; std::getline(ss, d, ':');)
        if (!d.empty() && std::ifstream(d + "/" + file).good())
            return cache[file] = std::make_shared<PreparedMesh>(prepare_mesh(load_mesh_file(d + "/" + file)));
    return cache[file] = nullptr;
}

/// The winding BVH of the mesh, built once.
const WindingSign& winding_of(const PreparedMesh& mesh, const WindingSignOptions& o) {
    static std::map<std::pair<const PreparedMesh*, std::string>, std::unique_ptr<WindingSign>> cache;
    const std::string key = std::to_string(o.accuracy.beta) + "/" + std::to_string(o.accuracy.order) + "/" + std::to_string(o.certify);
    auto& slot = cache[{&mesh, key}];
    if (!slot) slot = std::make_unique<WindingSign>(mesh, mesh.bvh(), o);
    return *slot;
}

Lattice cubic_lattice(const PreparedMesh& mesh, int r) { return fit_lattice(LatticeType::CC, {r, r, r}, mesh.bounds(), 0.1); }

void count(benchmark::State& state, int64_t points, int threads) {
    state.counters["points/s"] = benchmark::Counter(double(points) * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["points"] = double(points);
    state.counters["threads"] = double(resolve_thread_count(threads));
}

void BM_UnsignedBvh(benchmark::State& state) {
    const auto mesh = load(mesh_file());
    if (!mesh) { state.SkipWithError("mesh not found: set SDF_DATA_PATH"); return; }
    const Lattice lattice = cubic_lattice(*mesh, int(state.range(0)));
    SamplerOptions o;
    o.method = "bvh";
    o.threads = int(state.range(1));
    o.progress = false;
    const auto sampler = make_cpu_bvh_sampler(o)->bind(share(mesh));  // the BVH (if not built yet) and sign data
    SampledField f = sampler->sample(lattice);
    for (auto _ : state) {
        f = sampler->sample(lattice);
        state.SetIterationTime(f.timings.kernel);
    }
    count(state, lattice.num_points(), o.threads);
}

/// Signs of the first `limit` lattice points (all when limit < 0); returns the inside count
/// and adds the points not decided by the first evaluation to `refined`.
int64_t sign_points(const WindingSign& sign, const Lattice& lattice, int threads, int64_t limit, int64_t& refined) {
    const int64_t n = limit < 0 ? lattice.num_points() : std::min(limit, lattice.num_points());
    std::atomic<int64_t> inside{0}, later{0};
    parallel_for(n, 256, threads, [&](int64_t begin, int64_t end) {
        int64_t local = 0, local_later = 0;
        for (int64_t i = begin; i < end; ++i) {
            const WindingSide side = sign.side(lattice.position(i));
            local += side.inside;
            local_later += side.stage != WindingStage::Fast;
        }
        inside += local;
        later += local_later;
    });
    refined += later.load();
    return inside.load();
}

void run_winding(benchmark::State& state, const WindingSignOptions& o, int64_t limit) {
    const auto mesh = load(mesh_file());
    if (!mesh) { state.SkipWithError("mesh not found: set SDF_DATA_PATH"); return; }
    const Lattice lattice = cubic_lattice(*mesh, int(state.range(0)));
    const WindingSign& sign = winding_of(*mesh, o);
    const int threads = int(state.range(1));
    int64_t inside = 0, refined = 0;
    for (auto _ : state) benchmark::DoNotOptimize(inside = sign_points(sign, lattice, threads, limit, refined));
    count(state, limit < 0 ? lattice.num_points() : std::min(limit, lattice.num_points()), threads);
    state.counters["inside"] = double(inside);
    state.counters["refined/it"] = double(refined) / double(state.iterations());
    state.counters["moments_s"] = sign.winding_bvh().seconds;
}

WindingSignOptions options(double beta, int order, bool certify) {
    WindingSignOptions o;
    o.accuracy = {beta, order};
    o.certify = certify;
    return o;
}

void BM_WindingFast(benchmark::State& state) {
    run_winding(state, options(double(state.range(2)) / 10.0, int(state.range(3)), false), -1);
}
void BM_WindingCertified(benchmark::State& state) {
    run_winding(state, options(double(state.range(2)) / 10.0, int(state.range(3)), true), -1);
}
void BM_WindingExact(benchmark::State& state) {
    run_winding(state, options(std::numeric_limits<double>::infinity(), 2, false), 512);
}

BENCHMARK(BM_UnsignedBvh)->Args({64, 1})->Args({64, 2})->Args({128, 2})->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WindingFast)
    ->Args({64, 1, 20, 2})->Args({64, 2, 20, 2})->Args({64, 1, 20, 1})->Args({64, 1, 30, 2})->Args({128, 2, 20, 2})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_WindingCertified)->Args({64, 1, 40, 2})->Args({64, 2, 40, 2})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_WindingExact)->Args({64, 1})->Args({64, 2})->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

}  // namespace
}  // namespace sdf

BENCHMARK_MAIN();
