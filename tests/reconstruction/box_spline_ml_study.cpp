// The efficiency claim of Entezari, Van De Ville and Moeller (IEEE TVCG 14(2), 2008) measured
// on the Marschner-Lobb function (f_M = 6, alpha = 0.25): RMS error against the number of
// samples for the BCC quintic box spline (approximating, quasi-interpolating, interpolating)
// and the CC tricubic B-spline (interpolating), and the sample-count ratio at which BCC
// matches CC's error. A program, not a test (it takes about a minute):
//   box_spline_ml_study [probes=200000] [threads=0]
//
// Samples are counted per the volume [-1,1]^3: 8/h^3 on CC, 16/h^3 on BCC (h its primary
// spacing). Each lattice extends 8h beyond [-1,1]^3, so the mirror boundary of the
// prefilters (kernels/reconstruction/spline_coefficients.h) does not reach the probes: its
// influence decays by 0.27 per h for the cubic B-spline and faster for the box spline. RMS
// over `probes` uniform random points of [-1,1]^3 (fixed seed), in the function's units.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "core/parallel/parallel_for.h"
#include "core/reconstruction/analytic_study.h"
#include "core/reconstruction/spline_prefilters.h"
#include "kernels/reconstruction/bcc_box_quintic.h"
#include "kernels/reconstruction/cc_bspline3.h"

namespace sdf {
namespace {

struct Row {
    double h = 0, samples = 0, rms = 0;
};

/// The lattice with spacing 2/intervals whose primary grid covers [-1 - 8h, 1 + 8h]^3.
Lattice padded_lattice(LatticeType type, int intervals) {
    const double h = 2.0 / intervals;
    const int n = intervals + 16 + 1;
    return lattice_spanning(type, {n, n, n}, Vec3d(-1 - 8 * h), Vec3d(1 + 8 * h));
}

template <typename I>
Row measure(int intervals, const std::vector<Vec3d>& probes, int threads) {
    const MarschnerLobb<double> f;
    HermiteData<double> d;
    d.lattice = padded_lattice(I::lattice_type(), intervals);
    d.values.resize(size_t(d.lattice.num_points()));
    parallel_for(d.lattice.num_points(), 4096, threads, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) d.values[size_t(i)] = f(d.lattice.position(i)).value;
    });
    build_spline_coefficients(d, I::prefilter(), threads);
    const LatticeFieldView<double> v = d.view();
    std::vector<double> sq(probes.size());
    parallel_for(int64_t(probes.size()), 4096, threads, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
            const double e = I::evaluate(v, probes[size_t(i)]).value - f(probes[size_t(i)]).value;
            sq[size_t(i)] = e * e;
        }
    });
    double sum = 0;
    for (double x : sq) sum += x;
    const double h = 2.0 / intervals;
    const double per_volume = I::lattice_type() == LatticeType::CC ? 8 / (h * h * h) : 16 / (h * h * h);
    return {h, per_volume, std::sqrt(sum / double(probes.size()))};
}

/// Samples a series needs to reach error e, by log-log interpolation between its rows
/// (errors decrease along the series); NAN outside its range.
double samples_for_error(const std::vector<Row>& series, double e) {
    for (size_t i = 0; i + 1 < series.size(); ++i) {
        const Row& a = series[i];
        const Row& b = series[i + 1];
        if ((a.rms - e) * (b.rms - e) > 0) continue;
        const double t = std::log(e / a.rms) / std::log(b.rms / a.rms);
        return std::exp(std::log(a.samples) + t * std::log(b.samples / a.samples));
    }
    return NAN;
}

template <typename I>
std::vector<Row> series(const std::vector<int>& intervals, const std::vector<Vec3d>& probes, int threads) {
    std::vector<Row> rows;
    for (int n : intervals) {
        rows.push_back(measure<I>(n, probes, threads));
        std::printf("  %-24s h = 2/%-4d samples %10.0f  RMS %.4e\n", I::name(), n, rows.back().samples, rows.back().rms);
        std::fflush(stdout);
    }
    return rows;
}

void print_order(const char* name, const std::vector<Row>& s) {
    std::printf("%-24s", name);
    for (size_t i = 0; i + 1 < s.size(); ++i) std::printf(" %6.2f", std::log(s[i].rms / s[i + 1].rms) / std::log(s[i].h / s[i + 1].h));
    std::printf("\n");
}

}  // namespace
}  // namespace sdf

int main(int argc, char** argv) {
    using namespace sdf;
    const int probe_count = argc > 1 ? std::atoi(argv[1]) : 200000;
    const int threads = argc > 2 ? std::atoi(argv[2]) : 0;
    if (probe_count <= 0) {
        std::fprintf(stderr, "box_spline_ml_study: probes must be a positive integer, got '%s'\n", argv[1]);
        return 1;
    }
    std::mt19937 rng(2008);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<Vec3d> probes(static_cast<size_t>(probe_count));
    for (Vec3d& p : probes) p = Vec3d(u(rng), u(rng), u(rng));
    // Spacings: CC n^3 samples per [-1,1]^3 from 24^3 to 128^3; BCC 2 m^3 over a similar range
    const std::vector<int> cc_intervals = {24, 32, 40, 48, 64, 80, 96, 128};
    const std::vector<int> bcc_intervals = {20, 25, 32, 40, 50, 64, 80, 100};
    std::printf("Marschner-Lobb (f_M = 6, alpha = 0.25), RMS error at %d random points of [-1,1]^3\n", probe_count);
    const auto cc = series<CcBspline3>(cc_intervals, probes, threads);
    const auto approx = series<BccBoxQuinticApprox>(bcc_intervals, probes, threads);
    const auto qi = series<BccBoxQuinticQi>(bcc_intervals, probes, threads);
    const auto interp = series<BccBoxQuintic>(bcc_intervals, probes, threads);
    std::printf("\nOrders between successive spacings (log e ratio / log h ratio):\n");
    print_order("cc_bspline3", cc);
    print_order("bcc_box_quintic_approx", approx);
    print_order("bcc_box_quintic_qi", qi);
    print_order("bcc_box_quintic", interp);
    std::printf("\nSamples CC needs / samples BCC needs for the same RMS error (> 1: BCC is more efficient):\n");
    std::printf("%10s %12s | %22s %22s %22s\n", "CC samples", "CC RMS", "bcc_box_quintic_approx", "bcc_box_quintic_qi",
                "bcc_box_quintic");
    for (const Row& r : cc) {
        std::printf("%10.0f %12.4e |", r.samples, r.rms);
        for (const auto* s : {&approx, &qi, &interp}) {
            const double n = samples_for_error(*s, r.rms);
            if (std::isnan(n))
                std::printf(" %22s", "out of range");
            else
                std::printf(" %22.2f", r.samples / n);
        }
        std::printf("\n");
    }
    return 0;
}
