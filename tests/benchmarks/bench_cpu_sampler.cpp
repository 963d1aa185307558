// Single-thread point-triangle pairs per second of the CPU brute-force kernels.
//   bench_cpu_sampler --benchmark_counters_tabular=true
// The vectorised kernel runs at the ISA level the samplers use (cpu_reference/dispatch):
// SDF_CPU_ISA=v2|v3|v4 chooses another.
#include <benchmark/benchmark.h>

#include <random>

#include "core/mesh/shapes/procedural_shapes.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "cpu_reference/dispatch/cpu_kernels.h"
#include "kernels/distance/signed_distance.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

const PreparedMesh& sphere_mesh() {
    static const PreparedMesh mesh = prepare_mesh(make_icosphere(5));  // 20,480 triangles
    return mesh;
}

std::vector<Vec3d> random_points(int n) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    std::vector<Vec3d> p(static_cast<size_t>(n));
    for (auto& q : p) q = {u(rng), u(rng), u(rng)};
    return p;
}

template <typename T>
void BM_NearestTriangleVectorized(benchmark::State& state) {
    const PreparedMesh& mesh = sphere_mesh();
    const TriangleSoA<T> soa(mesh.buffers<T>().packed);
    const auto pts = random_points(kPointTile);
    T px[kPointTile], py[kPointTile], pz[kPointTile], q[kPointTile];
    int best[kPointTile];
    for (int k = 0; k < kPointTile; ++k) { px[k] = T(pts[k].x); py[k] = T(pts[k].y); pz[k] = T(pts[k].z); }
    const auto nearest_triangles = cpu_kernels<T>().nearest_triangles;
    state.SetLabel(active_cpu_kernels().isa);
    for (auto _ : state) {
        nearest_triangles(soa, kPointTile, px, py, pz, best, q);
        benchmark::DoNotOptimize(best);
    }
    const double pairs = double(state.iterations()) * kPointTile * soa.size();
    state.counters["pairs/s"] = benchmark::Counter(pairs, benchmark::Counter::kIsRate);
}
BENCHMARK_TEMPLATE(BM_NearestTriangleVectorized, float)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_NearestTriangleVectorized, double)->Unit(benchmark::kMillisecond);

template <typename T>
void BM_NearestTriangleEberly(benchmark::State& state) {
    const PreparedMesh& mesh = sphere_mesh();
    const MeshView<T> view = mesh.buffers<T>().view();
    const auto pts = random_points(4);
    for (auto _ : state)
        for (const Vec3d& p : pts) benchmark::DoNotOptimize(nearest_triangle_eberly(view, Vec3<T>(p)));
    const double pairs = double(state.iterations()) * double(pts.size()) * view.num_triangles;
    state.counters["pairs/s"] = benchmark::Counter(pairs, benchmark::Counter::kIsRate);
}
BENCHMARK_TEMPLATE(BM_NearestTriangleEberly, float)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_NearestTriangleEberly, double)->Unit(benchmark::kMillisecond);

/// The whole single-threaded sampler on a 32^3 CC lattice (includes the final Eberly pass).
void BM_CpuSamplerSingleThread(benchmark::State& state) {
    const PreparedMesh& mesh = sphere_mesh();
    SamplerOptions options;
    options.threads = 1;
    options.progress = false;
    const auto sampler = make_cpu_brute_force_sampler(options)->bind(share(mesh));
    Lattice lattice{LatticeType::CC, {-1.5, -1.5, -1.5}, 3.0 / 15, {16, 16, 16}};
    double pairs = 0;
    for (auto _ : state) {
        SampledField f = sampler->sample(lattice);
        pairs += f.timings.point_triangle_pairs;
    }
    state.counters["pairs/s"] = benchmark::Counter(pairs, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_CpuSamplerSingleThread)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sdf

BENCHMARK_MAIN();
