// Single-thread evaluations per second (value + gradient) of every interpolator and
// derivative source, on the CPU, in double and in float, at random points (/random: every
// evaluation touches cold lattice data) and at the same points sorted along z-slices
// (/coherent: neighbouring evaluations share lattice data, as a ray caster's do).
//   bench_reconstruction --benchmark_counters_tabular=true
// Fields: TrigFunction (scale 4) on a 64^3 CC lattice and on a 51x51x102 BCC lattice (matched
// sample counts: 262,144 vs 257,651), 4096 fixed random points inside the domain. The
// derivative arrays are built once, outside the timing (hermite_data.h).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/reconstruction/analytic_study.h"

namespace sdf {
namespace {

constexpr int kPoints = 4096;

const SampledField& field_for(LatticeType type) {
    static const SampledField cc = sample_analytic_field(
        lattice_spanning(LatticeType::CC, {64, 64, 64}, Vec3d(0.0), Vec3d(1.0)), TrigFunction<double>{4.0});
    static const SampledField bcc = sample_analytic_field(
        lattice_spanning(LatticeType::BCC, {51, 51, 51}, Vec3d(0.0), Vec3d(1.0)), TrigFunction<double>{4.0});
    return type == LatticeType::CC ? cc : bcc;
}

template <typename T>
void evaluations(benchmark::State& state, ReconstructionSpec spec, bool coherent) {
    spec.threads = 1;
    const Reconstruction recon(field_for(interpolator_lattice(spec.interpolator)), spec);
    const HermiteData<T> data = convert_hermite_data<T>(recon.data());
    const LatticeFieldView<T> view = data.view();
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0, 1);
    const DomainBox<double> box = recon.domain();
    std::vector<Vec3<T>> points;
    for (int i = 0; i < kPoints; ++i) {
        // coherent: a thin slab, sorted along x, so consecutive points share cells
        const double x = u(rng), y = coherent ? 0.5 + 0.02 * u(rng) : u(rng), z = coherent ? 0.5 + 0.02 * u(rng) : u(rng);
        points.emplace_back(box.lo + component_mul(box.hi - box.lo, Vec3d(x, y, z)));
    }
    if (coherent) std::sort(points.begin(), points.end(), [](const Vec3<T>& a, const Vec3<T>& b) { return a.x < b.x; });
    visit_interpolator(spec.interpolator, [&](auto interp) {
        using Interp = decltype(interp);
        for (auto _ : state)
            for (const Vec3<T>& p : points) benchmark::DoNotOptimize(Interp::evaluate(view, p));
        return 0;
    });
    state.counters["evals/s"] = benchmark::Counter(double(state.iterations()) * kPoints, benchmark::Counter::kIsRate);
}

void register_all() {
    for (const std::string& name : interpolator_names()) {
        const InterpolatorKind kind = parse_interpolator(name);
        for (DerivativeSource source : valid_derivative_sources(kind)) {
            ReconstructionSpec spec{kind, source};
            const std::string label = name + "/" + derivative_source_name(source);
            for (bool coherent : {false, true}) {
                const std::string suffix = label + (coherent ? "/coherent" : "/random");
                benchmark::RegisterBenchmark(("BM_Evaluate<double>/" + suffix).c_str(), evaluations<double>, spec, coherent)
                    ->Unit(benchmark::kMicrosecond);
                benchmark::RegisterBenchmark(("BM_Evaluate<float>/" + suffix).c_str(), evaluations<float>, spec, coherent)
                    ->Unit(benchmark::kMicrosecond);
            }
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
