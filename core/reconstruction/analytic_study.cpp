#include "core/reconstruction/analytic_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/lattice/lattice_fitting.h"
#include "core/parallel/parallel_for.h"

namespace sdf {
namespace {

/// Per-chunk sums, merged in chunk order so results do not depend on the thread count.
struct ErrorSums {
    double squares = 0, abs = 0, max_abs = 0, gradient_squares = 0;
};

/// SplitMix64 (Steele, Lea, Flood 2014) of a counter: a uniform double in [0, 1) per
/// (index, axis), independent of the order and the threads that ask.
double counter_uniform(uint64_t counter) {
    uint64_t z = counter + 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return double(z >> 11) * 0x1.0p-53;
}

Vec3d probe_position(const DomainBox<double>& box, int n, int64_t index, bool random) {
    Vec3d t;
    if (random) {
        const uint64_t c = 3 * uint64_t(index);
        t = Vec3d(counter_uniform(c), counter_uniform(c + 1), counter_uniform(c + 2));
    } else {
        const int64_t i = index % n, j = (index / n) % n, k = index / (int64_t(n) * n);
        t = Vec3d((double(i) + 0.5) / n, (double(j) + 0.5) / n, (double(k) + 0.5) / n);
    }
    return box.lo + component_mul(box.hi - box.lo, t);
}

}  // namespace

AnalyticSample<double> evaluate_analytic(const std::string& function, const Vec3d& p) {
    if (function == "marschner_lobb") return MarschnerLobb<double>{}(p);
    if (function == "trig") return TrigFunction<double>{}(p);
    throw std::invalid_argument("unknown analytic function '" + function + "'; expected marschner_lobb or trig");
}

Lattice lattice_spanning(LatticeType type, Int3 resolution, const Vec3d& lo, const Vec3d& hi) {
    const double h = (hi.x - lo.x) / (resolution.x - 1);
    for (int a = 0; a < 3; ++a)
        if (resolution[a] < 2 || std::abs((hi[a] - lo[a]) - h * (resolution[a] - 1)) > 1e-9 * std::abs(hi[a] - lo[a]))
            throw std::invalid_argument("lattice_spanning: the box and resolution need one isotropic spacing");
    Lattice l;
    l.type = type;
    l.origin = lo;
    l.spacing = h;
    l.resolution = resolution;
    return l;
}

AnalyticStudyResult run_analytic_study(const AnalyticStudySpec& spec) {
    const auto f = [&](const Vec3d& p) { return evaluate_analytic(spec.function, p); };
    const Lattice lattice = lattice_spanning(spec.lattice, spec.resolution, spec.domain_min, spec.domain_max);
    if (spec.padding < 0) throw std::invalid_argument("analytic study: padding must be >= 0 spacings");
    const Vec3d pad(spec.padding * lattice.spacing);
    const int grow = 2 * spec.padding;
    const Lattice sampled =
        spec.padding == 0 ? lattice
                          : lattice_spanning(spec.lattice, {spec.resolution.x + grow, spec.resolution.y + grow, spec.resolution.z + grow},
                                             spec.domain_min - pad, spec.domain_max + pad);
    ReconstructionSpec rspec = spec.reconstruction;
    rspec.threads = spec.threads;
    const SampledField field = sample_analytic_field(sampled, f);
    const auto build_start = std::chrono::steady_clock::now();
    const Reconstruction recon(field, rspec);
    const double prepare_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();

    AnalyticStudyResult r;
    r.description = spec.function + " / " + recon.description();
    r.lattice = lattice_notation(lattice);
    r.lattice_points = lattice.num_points();
    r.probe_box = recon.domain();
    const Vec3d inset(spec.margin * lattice.spacing);
    r.probe_box = {r.probe_box.lo + inset, r.probe_box.hi - inset};
    r.padding = spec.padding;
    r.random_probes = spec.random_probes;
    for (int a = 0; a < 3; ++a) {  // probes stay inside the box the samples are counted over
        r.probe_box.lo[a] = std::max(r.probe_box.lo[a], spec.domain_min[a]);
        r.probe_box.hi[a] = std::min(r.probe_box.hi[a], spec.domain_max[a]);
    }
    for (int a = 0; a < 3; ++a)
        if (!(r.probe_box.lo[a] < r.probe_box.hi[a]))
            throw std::invalid_argument("analytic study: margin " + std::to_string(spec.margin) +
                                        " h leaves no probe box on this lattice");
    const int n = spec.probes_per_axis;
    r.probes = int64_t(n) * n * n;
    const int64_t chunk = int64_t(n) * n;  // one z slice
    std::vector<ErrorSums> slices(static_cast<size_t>(n));
    parallel_for(r.probes, chunk, spec.threads, [&](int64_t begin, int64_t end) {
        ErrorSums& s = slices[size_t(begin / chunk)];
        for (int64_t i = begin; i < end; ++i) {
            const Vec3d p = probe_position(r.probe_box, n, i, spec.random_probes);
            const ReconstructedSample<double> got = recon.evaluate(p);
            const AnalyticSample<double> want = f(p);
            const double e = got.value - want.value;
            s.squares += e * e;
            s.abs += std::abs(e);
            s.max_abs = std::max(s.max_abs, std::abs(e));
            s.gradient_squares += length_squared(got.gradient - want.gradient);
        }
    });
    ErrorSums total;
    for (const ErrorSums& s : slices) {
        total.squares += s.squares;
        total.abs += s.abs;
        total.max_abs = std::max(total.max_abs, s.max_abs);
        total.gradient_squares += s.gradient_squares;
    }
    const double count = double(r.probes);
    r.rms = std::sqrt(total.squares / count);
    r.max_abs = total.max_abs;
    r.mean_abs = total.abs / count;
    r.l2_norm = std::sqrt(total.squares);
    r.rms_255 = 255.0 * r.rms;
    r.l2_norm_255 = 255.0 * r.l2_norm;
    r.gradient_rms = std::sqrt(total.gradient_squares / count);

    // Speed at probes spread over the whole grid (every stride-th), not one corner of it.
    const int64_t timed = std::min<int64_t>(r.probes, int64_t(1) << 16);
    std::vector<Vec3d> timing_points(static_cast<size_t>(timed));
    for (int64_t i = 0; i < timed; ++i) timing_points[size_t(i)] = probe_position(r.probe_box, n, i * (r.probes / timed), spec.random_probes);
    const EvaluationTiming timing = time_evaluation(recon, timing_points);
    r.prepare_seconds = prepare_seconds;
    r.eval_ns_per_point = timing.ns_per_point;
    r.timed_points = timing.points;
    return r;
}

nlohmann::json to_json(const AnalyticStudyResult& r) {
    return {{"description", r.description},
            {"lattice", r.lattice},
            {"lattice_points", r.lattice_points},
            {"padding_spacings", r.padding},
            {"random_probes", r.random_probes},
            {"probes", r.probes},
            {"probe_box", {{r.probe_box.lo.x, r.probe_box.lo.y, r.probe_box.lo.z},
                           {r.probe_box.hi.x, r.probe_box.hi.y, r.probe_box.hi.z}}},
            {"rms", r.rms},
            {"max_abs", r.max_abs},
            {"mean_abs", r.mean_abs},
            {"l2_norm", r.l2_norm},
            {"rms_255", r.rms_255},
            {"l2_norm_255", r.l2_norm_255},
            {"gradient_rms", r.gradient_rms},
            {"prepare_seconds", r.prepare_seconds},
            {"eval_ns_per_point", r.eval_ns_per_point},
            {"timed_points", r.timed_points}};
}

}  // namespace sdf
