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
    // Chunks short against a scheduler's time slice (about 0.1-1 ms each), each timed
    // `repetitions` times and its fastest pass kept: on a loaded machine most chunks then have
    // one uninterrupted pass, which a single long pass almost never has.
    constexpr int64_t kChunk = 1024;
    EvaluationTiming t;
    t.points = std::min(int64_t(points.size()), max_points);
    t.repetitions = std::max(1, repetitions);
    if (t.points == 0) return t;
    std::vector<ReconstructedSample<double>> out(static_cast<size_t>(std::min(t.points, kChunk)));
    double total = 0;
    for (int64_t begin = 0; begin < t.points; begin += kChunk) {
        const int64_t n = std::min(kChunk, t.points - begin);
        double best = 0;
        for (int r = 0; r < t.repetitions; ++r) {
            const auto start = std::chrono::steady_clock::now();
            recon.evaluate(points.data() + begin, out.data(), n, 1);
            const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            best = r == 0 ? s : std::min(best, s);
        }
        total += best;
    }
    t.ns_per_point = 1e9 * total / double(t.points);
    return t;
}

}  // namespace sdf
