// Field.reconstruct's and SparseField.reconstruct's shared steps (reconstruct.h).
#include "python/src/reconstruct.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "harness/resources/memory_budget.h"
#include "python/src/task.h"

namespace sdf {

ReconstructionSpec reconstruction_spec(LatticeType lattice, bool has_gradient, const std::string& interpolator_in,
                                       const std::string& derivatives, double sigma2, const std::string& sigma_units,
                                       int threads) {
    if (!(sigma2 > 0 && std::isfinite(sigma2)))
        throw std::invalid_argument("sigma2: expected a finite variance > 0, got " + number_text(sigma2));
    const std::string interpolator =
        interpolator_in.empty() ? (lattice == LatticeType::BCC ? "bcc_cubic" : "tricubic_lm") : interpolator_in;
    ReconstructionSpec spec;
    spec.interpolator = parse_interpolator(interpolator);
    spec.derivatives = derivatives.empty() ? default_derivative_source(spec.interpolator, has_gradient)
                                           : parse_derivative_source(derivatives);
    spec.sigma2 = sigma2;
    spec.sigma_units = choose("sigma_units", sigma_units, {"lattice", "spacing"}) == "lattice" ? SigmaUnits::LatticeUnits
                                                                                                : SigmaUnits::Spacing;
    if (threads < 0) throw std::invalid_argument("threads: expected 0 (all cores) or a positive count");
    spec.threads = threads;
    return spec;
}

std::pair<std::vector<Vec3d>, std::vector<ReconstructedSample<double>>> reconstruct_points(
    const DoubleArray& array, const std::function<std::vector<ReconstructedSample<double>>(const std::vector<Vec3d>&)>& evaluate) {
    // What a call holds per point: the points, the samples and the two result arrays.
    const auto out_of_memory = [&] {
        const uint64_t n = array.ndim() == 2 ? uint64_t(array.shape(0)) : uint64_t(array.size());
        raise_memory_error("reconstruct(): out of memory for " + std::to_string(n) + " points (about " +
                           format_bytes(n * (sizeof(Vec3d) + sizeof(ReconstructedSample<double>) + 4 * sizeof(double))) +
                           "); reconstruct fewer points per call");
    };
    std::vector<Vec3d> points;
    std::vector<ReconstructedSample<double>> samples;
    try {
        points = points_from_array(array, "points");
        TaskOptions task;
        task.total = int64_t(points.size());
        task.label = "reconstructing";
        samples = run_task([&] { return evaluate(points); }, task);
    } catch (const std::bad_alloc&) {
        out_of_memory();
    } catch (py::error_already_set& e) {
        if (e.matches(PyExc_MemoryError)) out_of_memory();
        throw;
    }
    return {std::move(points), std::move(samples)};
}

py::tuple reconstruction_arrays(const std::vector<Vec3d>& points, const std::vector<ReconstructedSample<double>>& samples,
                                const DomainBox<double>& d, const std::string& outside) {
    choose("outside", outside, {"nan", "clamp", "error"});
    const size_t n = samples.size();
    if (outside == "error")
        for (size_t i = 0; i < n; ++i)
            if (!samples[i].inside) {
                std::ostringstream m;
                m << "points: row " << i << " (" << points[i].x << ", " << points[i].y << ", " << points[i].z
                  << ") lies outside the field's domain [" << d.lo.x << ", " << d.hi.x << "] x [" << d.lo.y << ", " << d.hi.y
                  << "] x [" << d.lo.z << ", " << d.hi.z << "] (outside=\"nan\" gives NaN there, \"clamp\" the nearest value inside)";
                throw std::invalid_argument(m.str());
            }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const bool to_nan = outside == "nan";
    auto values = new_array<double>({py::ssize_t(n)}, [&](double* v) {
        for (size_t i = 0; i < n; ++i) v[i] = to_nan && !samples[i].inside ? nan : samples[i].value;
    });
    auto gradients = new_array<double>({py::ssize_t(n), 3}, [&](double* g) {
        for (size_t i = 0; i < n; ++i) {
            const bool blank = to_nan && !samples[i].inside;
            g[3 * i] = blank ? nan : samples[i].gradient.x;
            g[3 * i + 1] = blank ? nan : samples[i].gradient.y;
            g[3 * i + 2] = blank ? nan : samples[i].gradient.z;
        }
    });
    return py::make_tuple(values, gradients);
}

}  // namespace sdf
