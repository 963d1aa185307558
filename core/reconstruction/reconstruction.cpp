#include "core/reconstruction/reconstruction.h"

#include <algorithm>
#include <chrono>

#include "core/parallel/parallel_for.h"

namespace sdf {
namespace {

ReconstructionSpec spec_from_names(const SampledField& field, const std::string& interpolator,
                                   const std::string& derivatives) {
    ReconstructionSpec spec;
    spec.interpolator = parse_interpolator(interpolator);
    spec.derivatives = derivatives.empty() ? default_derivative_source(spec.interpolator, !field.gradient.empty())
                                           : parse_derivative_source(derivatives);
    return spec;
}

}  // namespace

Reconstruction::Reconstruction(const SampledField& field, const ReconstructionSpec& spec)
    : spec_(spec), data_(std::make_unique<HermiteData<double>>(build_hermite_data(field, spec))), view_(data_->view()) {}

Reconstruction::Reconstruction(const SampledField& field, const std::string& interpolator, const std::string& derivatives)
    : Reconstruction(field, spec_from_names(field, interpolator, derivatives)) {}

DomainBox<double> Reconstruction::domain() const {
    return visit_interpolator(spec_.interpolator, [&](auto interp) { return decltype(interp)::domain(view_); });
}

ReconstructedSample<double> Reconstruction::evaluate(const Vec3d& p) const {
    return visit_interpolator(spec_.interpolator, [&](auto interp) { return decltype(interp)::evaluate(view_, p); });
}

void Reconstruction::evaluate(const Vec3d* points, ReconstructedSample<double>* out, int64_t n, int threads) const {
    visit_interpolator(spec_.interpolator, [&](auto interp) {
        using Interp = decltype(interp);
        parallel_for(n, 1024, threads, [&](int64_t begin, int64_t end) {
            for (int64_t i = begin; i < end; ++i) out[i] = Interp::evaluate(view_, points[i]);
        });
        return 0;
    });
}

std::vector<ReconstructedSample<double>> Reconstruction::evaluate(const std::vector<Vec3d>& points, int threads) const {
    std::vector<ReconstructedSample<double>> out(points.size());
    evaluate(points.data(), out.data(), int64_t(points.size()), threads);
    return out;
}

EvaluationTiming time_evaluation(const Reconstruction& recon, const std::vector<Vec3d>& points, int64_t max_points,
                                 int repetitions) {
    EvaluationTiming t;
    t.points = std::min(int64_t(points.size()), max_points);
    t.repetitions = std::max(1, repetitions);
    if (t.points == 0) return t;
    std::vector<ReconstructedSample<double>> out(static_cast<size_t>(t.points));
    double best = 0;
    for (int r = 0; r < t.repetitions; ++r) {
        const auto start = std::chrono::steady_clock::now();
        recon.evaluate(points.data(), out.data(), t.points, 1);
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        best = r == 0 ? s : std::min(best, s);
    }
    t.ns_per_point = 1e9 * best / double(t.points);
    return t;
}

}  // namespace sdf
