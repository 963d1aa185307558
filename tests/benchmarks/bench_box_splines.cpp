// Single-thread evaluations per second (value + gradient) of the spline filters of issue 17
// (bcc_box_linear, bcc_box_quintic with its three prefilters, cc_bspline3), beside the
// filters they are compared with, measured in the same run and on the same fields as
// bench_reconstruction: TrigFunction (scale 4) on a 64^3 CC lattice and a 51x51x102 BCC
// lattice (262,144 vs 257,651 samples), 4096 fixed random points inside each filter's
// domain, /random (scattered) and /coherent (a thin slab sorted along x, as along a ray).
// The prefilters run once, outside the timing.
//   bench_box_splines --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "core/reconstruction/analytic_study.h"
#include "core/reconstruction/spline_prefilters.h"
#include "kernels/reconstruction/bcc_box_linear.h"
#include "kernels/reconstruction/bcc_box_quintic.h"
#include "kernels/reconstruction/cc_bspline3.h"

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
std::vector<Vec3<T>> probe_points(const DomainBox<double>& box, bool coherent) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<Vec3<T>> points;
    for (int i = 0; i < kPoints; ++i) {
        const double x = u(rng), y = coherent ? 0.5 + 0.02 * u(rng) : u(rng), z = coherent ? 0.5 + 0.02 * u(rng) : u(rng);
        points.emplace_back(box.lo + component_mul(box.hi - box.lo, Vec3d(x, y, z)));
    }
    if (coherent) std::sort(points.begin(), points.end(), [](const Vec3<T>& a, const Vec3<T>& b) { return a.x < b.x; });
    return points;
}

template <typename Interp, typename T>
void run(benchmark::State& state, const HermiteData<double>& data, bool coherent) {
    const HermiteData<T> converted = convert_hermite_data<T>(data);
    const LatticeFieldView<T> view = converted.view();
    const LatticeFieldView<double> view_d = data.view();
    const std::vector<Vec3<T>> points = probe_points<T>(Interp::domain(view_d), coherent);
    for (auto _ : state)
        for (const Vec3<T>& p : points) benchmark::DoNotOptimize(Interp::evaluate(view, p));
    state.counters["evals/s"] = benchmark::Counter(double(state.iterations()) * kPoints, benchmark::Counter::kIsRate);
}

/// A spline filter of issue 17: values plus its prefilter's coefficients.
template <typename Interp, typename T>
void spline_filter(benchmark::State& state, bool coherent) {
    const SampledField& field = field_for(Interp::lattice_type());
    HermiteData<double> data;
    data.lattice = field.lattice;
    data.values = field.distance;
    build_spline_coefficients(data, Interp::prefilter(), 1);
    run<Interp, T>(state, data, coherent);
}

/// A filter of the existing list, through the host Reconstruction.
template <typename Interp, typename T>
void reference_filter(benchmark::State& state, ReconstructionSpec spec, bool coherent) {
    spec.threads = 1;
    const Reconstruction recon(field_for(Interp::lattice_type()), spec);
    run<Interp, T>(state, recon.data(), coherent);
}

template <typename Interp>
void register_spline() {
    for (bool coherent : {false, true}) {
        const std::string suffix = std::string(Interp::name()) + (coherent ? "/coherent" : "/random");
        benchmark::RegisterBenchmark(("BM_Evaluate<double>/" + suffix).c_str(), spline_filter<Interp, double>, coherent)
            ->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark(("BM_Evaluate<float>/" + suffix).c_str(), spline_filter<Interp, float>, coherent)
            ->Unit(benchmark::kMicrosecond);
    }
}

template <typename Interp>
void register_reference(InterpolatorKind kind, DerivativeSource source) {
    const ReconstructionSpec spec{kind, source};
    for (bool coherent : {false, true}) {
        const std::string suffix = std::string(Interp::name()) + "/" + derivative_source_name(source) +
                                   (coherent ? "/coherent" : "/random");
        benchmark::RegisterBenchmark(("BM_Evaluate<double>/" + suffix).c_str(), reference_filter<Interp, double>, spec,
                                     coherent)
            ->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark(("BM_Evaluate<float>/" + suffix).c_str(), reference_filter<Interp, float>, spec,
                                     coherent)
            ->Unit(benchmark::kMicrosecond);
    }
}

void register_all() {
    register_spline<BccBoxLinear>();
    register_spline<BccBoxQuinticApprox>();
    register_spline<BccBoxQuinticQi>();
    register_spline<BccBoxQuintic>();
    register_spline<CcBspline3>();
    register_reference<Trilinear>(kind_of<Trilinear>(), DerivativeSource::FiniteDifferences);
    register_reference<CatmullRom>(kind_of<CatmullRom>(), DerivativeSource::FiniteDifferences);
    register_reference<TricubicLekienMarsden>(kind_of<TricubicLekienMarsden>(), DerivativeSource::True);
    register_reference<BccLinear>(kind_of<BccLinear>(), DerivativeSource::FiniteDifferences);
    register_reference<BccCubic>(kind_of<BccCubic>(), DerivativeSource::FiniteDifferences);
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
