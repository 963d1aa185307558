#include "core/reconstruction/sparse_reconstruction.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "core/parallel/parallel_for.h"
#include "core/sampling/sparse_band_window.h"

namespace sdf {
namespace {

/// The block of cells that groups points: 8 primary cells per axis, as the band's blocks.
constexpr int kCellBlock = kBandBlockDim;

ReconstructionSpec spec_from_names(const std::string& interpolator, const std::string& derivatives, bool gradient) {
    ReconstructionSpec spec;
    spec.interpolator = parse_interpolator(interpolator);
    spec.derivatives = derivatives.empty() ? default_derivative_source(spec.interpolator, gradient)
                                           : parse_derivative_source(derivatives);
    return spec;
}

/// The geometry of the dense view (HermiteData::view()'s), without arrays.
LatticeFieldView<double> frame_of(const Lattice& lattice) {
    LatticeFieldView<double> v;
    v.lattice = lattice;
    v.origin = lattice.origin;
    const double unit = lattice.type == LatticeType::CC ? lattice.spacing : lattice.half_spacing();
    v.unit = unit;
    v.inv_unit = 1.0 / unit;
    return v;
}

}  // namespace

bool reconstructs_locally(InterpolatorKind kind) {
    return interpolator_point_data(kind) != PointData::SplineInterpolation;
}

SparseReconstruction::SparseReconstruction(const SparseBandField& band, const ReconstructionSpec& spec, bool gradient)
    : band_(band), spec_(spec), gradient_(gradient), frame_(frame_of(band.lattice)) {
    if (gradient && (!band.channels.gradient || band.gradient.size() != band.distance.size()))
        throw std::invalid_argument("sparse band has " + std::to_string(band.gradient.size()) + " gradients for " +
                                    std::to_string(band.distance.size()) + " values");
    validate_reconstruction(spec_, band.lattice, gradient);
    if (!reconstructs_locally(spec_.interpolator))
        throw std::invalid_argument(std::string("interpolator '") + interpolator_name(spec_.interpolator) +
                                    "': its interpolation prefilter solves over the whole lattice, so a sparse band "
                                    "reconstructs it only densified");
    // The interpolator's footprint in primary points beyond its cell, plus 2 for the
    // derivative sources' stencils (one point on CC, one primary spacing for the BCC fits)
    // and 1 for their edge rules (one-sided stencils within a point or two of an edge).
    margin_ = visit_interpolator(spec_.interpolator, [](auto interp) { return decltype(interp)::radius(); }) + 3;
}

SparseReconstruction::SparseReconstruction(const SparseBandField& band, const std::string& interpolator,
                                           const std::string& derivatives, bool gradient)
    : SparseReconstruction(band, spec_from_names(interpolator, derivatives, gradient), gradient) {}

DomainBox<double> SparseReconstruction::domain() const {
    return visit_interpolator(spec_.interpolator, [&](auto interp) { return decltype(interp)::domain(frame_); });
}

Int3 SparseReconstruction::cell_of(const Vec3d& u) const {
    const Int3 r = band_.lattice.resolution;
    const bool bcc = band_.lattice.type == LatticeType::BCC;
    Int3 cell;
    for (int a = 0; a < 3; ++a) {
        // The lattice's box in lattice units (CC: [0, r - 1]; BCC: [0, 2r - 2]), NaN to 0:
        // a point clamped by the interpolator has its window at that edge.
        const double top = bcc ? 2.0 * (r[a] - 1) : double(r[a] - 1);
        const double q = u[a] >= 0 ? (u[a] <= top ? u[a] : top) : 0.0;
        const int c = int(std::floor(bcc ? q / 2 : q));
        cell[a] = std::max(0, std::min(c, r[a] - 2));
    }
    return cell;
}

void SparseReconstruction::evaluate_group(const Int3& lo, const Int3& hi, const Vec3d* points, const int64_t* order,
                                          int64_t count, ReconstructedSample<double>* out) const {
    const Int3 r = band_.lattice.resolution;
    LatticeWindow window;
    for (int a = 0; a < 3; ++a) {
        window.first[a] = std::max(0, lo[a] - margin_);
        window.resolution[a] = std::min(r[a] - 1, hi[a] + 1 + margin_) - window.first[a] + 1;
    }
    const SampledField field = densify_window(band_, window, gradient_);
    ReconstructionSpec spec = spec_;
    spec.threads = 1;  // the groups run in parallel
    const HermiteData<double> data = build_hermite_data(field, spec);
    // The window in lattice units: origin 0, unit 1, so that the interpolator sees u - first
    // exactly (see the file's comment).
    LatticeFieldView<double> view = data.view();
    view.origin = Vec3d(0.0);
    view.unit = 1.0;
    view.inv_unit = 1.0;
    const int step = band_.lattice.type == LatticeType::BCC ? 2 : 1;  // lattice units per primary spacing
    const Vec3d shift(double(step * window.first.x), double(step * window.first.y), double(step * window.first.z));
    visit_interpolator(spec_.interpolator, [&](auto interp) {
        using Interp = decltype(interp);
        for (int64_t k = 0; k < count; ++k) {
            const int64_t i = order[k];
            ReconstructedSample<double> s = Interp::evaluate(view, frame_.to_lattice(points[i]) - shift);
            s.gradient = s.gradient * frame_.inv_unit;
            out[i] = s;
        }
        return 0;
    });
}

ReconstructedSample<double> SparseReconstruction::evaluate(const Vec3d& p) const {
    ReconstructedSample<double> s;
    const int64_t zero = 0;
    const Int3 cell = cell_of(frame_.to_lattice(p));
    evaluate_group(cell, cell, &p, &zero, 1, &s);
    return s;
}

void SparseReconstruction::evaluate(const Vec3d* points, ReconstructedSample<double>* out, int64_t n, int threads) const {
    if (n <= 0) return;
    // Points sorted by their block of cells; one window per block.
    const Int3 r = band_.lattice.resolution;
    const int64_t bx = (r.x - 2) / kCellBlock + 1, by = (r.y - 2) / kCellBlock + 1;
    std::vector<std::pair<int64_t, int64_t>> keyed(static_cast<size_t>(n));
    parallel_for(n, 4096, threads, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
            const Int3 c = cell_of(frame_.to_lattice(points[i]));
            keyed[size_t(i)] = {c.x / kCellBlock + bx * (c.y / kCellBlock + by * int64_t(c.z / kCellBlock)), i};
        }
    });
    std::sort(keyed.begin(), keyed.end());
    std::vector<int64_t> order(static_cast<size_t>(n)), starts;
    for (int64_t i = 0; i < n; ++i) {
        order[size_t(i)] = keyed[size_t(i)].second;
        if (i == 0 || keyed[size_t(i)].first != keyed[size_t(i - 1)].first) starts.push_back(i);
    }
    starts.push_back(n);
    keyed = {};
    parallel_for(int64_t(starts.size()) - 1, 1, threads, [&](int64_t begin, int64_t end) {
        for (int64_t g = begin; g < end; ++g) {
            const int64_t first = starts[size_t(g)], count = starts[size_t(g) + 1] - first;
            // The window covers the cells the group's points lie in (a few scattered points
            // need no window of the whole block).
            Int3 lo = cell_of(frame_.to_lattice(points[order[size_t(first)]])), hi = lo;
            for (int64_t k = 1; k < count; ++k) {
                const Int3 c = cell_of(frame_.to_lattice(points[order[size_t(first + k)]]));
                for (int a = 0; a < 3; ++a) {
                    lo[a] = std::min(lo[a], c[a]);
                    hi[a] = std::max(hi[a], c[a]);
                }
            }
            evaluate_group(lo, hi, points, order.data() + first, count, out);
        }
    });
}

std::vector<ReconstructedSample<double>> SparseReconstruction::evaluate(const std::vector<Vec3d>& points, int threads) const {
    std::vector<ReconstructedSample<double>> out(points.size());
    evaluate(points.data(), out.data(), int64_t(points.size()), threads);
    return out;
}

}  // namespace sdf
