// Google Benchmark of the polygon triangulation every mesh reader uses
// (core/mesh/polygon_triangulation.h, issue 38): simple polygons (a star with every other
// corner reflex, a comb whose base ears span every tooth) and polygons that cross themselves
// (random corners, a circle wound three times, a star polygon {n/137}, a figure of eight), of
// 10,000 to 160,000 corners; and the quadratic clipper it replaced
// (tests/core/mesh/reference_ear_clipping.h) on the smaller ones. Compare "corners/s" across
// sizes: n log n keeps it nearly flat, a quadratic clipper halves it per doubling.
//   bench_polygon_triangulation --benchmark_counters_tabular=true [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/mesh/polygon_triangulation.h"
#include "tests/core/mesh/reference_ear_clipping.h"

namespace sdf {
namespace {

constexpr double kPi = 3.14159265358979323846;

enum Shape { Star, Comb, RandomCorners, WoundThrice, StarPolygon, FigureOfEight };

std::vector<Vec3d> polygon(Shape shape, int n) {
    std::mt19937_64 rng(uint64_t(n) * 7 + uint64_t(shape));
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Vec3d> v;
    if (shape == Comb) {  // n / 4 teeth
        const int teeth = n / 4;
        v = {{0, 0, 0}, {2.0 * teeth, 0, 0}};
        for (int k = teeth - 1; k >= 0; --k)
            for (const auto& q : {Vec3d{2.0 * k + 2, 3, 0}, {2.0 * k + 1.5, 3, 0}, {2.0 * k + 1.5, 1, 0}, {2.0 * k + 1, 1, 0}})
                v.push_back(q);
        v.resize(v.size() - 2);
        v.push_back({0, 3, 0});
        return v;
    }
    for (int i = 0; i < n; ++i) {
        const double t = 2 * kPi * i / n;
        switch (shape) {
            case Star: v.push_back(Vec3d{std::cos(t), std::sin(t), 0} * (i % 2 ? 1.0 : 0.9)); break;
            case RandomCorners: v.push_back({u(rng), u(rng), 0}); break;
            case WoundThrice: {
                const double r = 1 + 0.2 * std::sin(7.3 * 3 * t) + 0.01 * u(rng);
                v.push_back({r * std::cos(3 * t), r * std::sin(3 * t), 0});
                break;
            }
            case StarPolygon: {
                const double a = 2 * kPi * double((int64_t(i) * 137) % n) / n;
                v.push_back({std::cos(a) * (1 + 1e-3 * u(rng)), std::sin(a), 0});
                break;
            }
            default: v.push_back({std::sin(t), std::sin(t) * std::cos(t) + 1e-4 * u(rng), 0}); break;
        }
    }
    return v;
}

template <bool kReference>
void BM_Triangulate(benchmark::State& state) {
    const std::vector<Vec3d> v = polygon(Shape(state.range(0)), int(state.range(1)));
    std::vector<int> corners(v.size());
    for (size_t i = 0; i < v.size(); ++i) corners[i] = int(i);
    for (auto _ : state) {
        std::vector<Int3> out;
        PolygonStats stats;
        if constexpr (kReference) reference::triangulate_polygon(v, corners, out, stats);
        else triangulate_polygon(v, corners, out, stats);
        benchmark::DoNotOptimize(out.data());
        state.counters["not_simple"] = double(stats.not_simple);
    }
    state.counters["corners"] = double(v.size());
    state.counters["corners/s"] = benchmark::Counter(double(v.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
}

void shapes(benchmark::internal::Benchmark* b, std::vector<int64_t> sizes) {
    b->ArgNames({"shape", "n"})->Unit(benchmark::kMillisecond);
    for (int64_t shape = Star; shape <= FigureOfEight; ++shape)
        for (const int64_t n : sizes) b->Args({shape, n});
}

BENCHMARK(BM_Triangulate<false>)->Apply([](benchmark::internal::Benchmark* b) { shapes(b, {10000, 40000, 160000}); });
BENCHMARK(BM_Triangulate<true>)->Apply([](benchmark::internal::Benchmark* b) { shapes(b, {2000, 5000}); });

}  // namespace
}  // namespace sdf

BENCHMARK_MAIN();
