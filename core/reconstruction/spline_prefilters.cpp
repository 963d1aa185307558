#include "core/reconstruction/spline_prefilters.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/parallel/parallel_for.h"
#include "kernels/reconstruction/bcc_box_quintic_table.h"

namespace sdf {
namespace {

constexpr int64_t kChunk = 4096;

void check_values(const Lattice& l, const std::vector<double>& values, LatticeType type, int min_resolution,
                  const char* filter) {
    const char* lattice_name = lattice_type_label(type);
    if (l.type != type)
        throw std::invalid_argument(std::string(filter) + " prefilter: needs a " + lattice_name + " lattice");
    for (int i = 0; i < 3; ++i)
        if (l.resolution[i] < min_resolution)
            throw std::invalid_argument(std::string(filter) + " prefilter: resolution " + std::to_string(l.resolution[i]) +
                                        " on axis " + std::to_string(i) + "; needs >= " + std::to_string(min_resolution));
    if (int64_t(values.size()) != l.num_points())
        throw std::invalid_argument(std::string(filter) + " prefilter: " + std::to_string(values.size()) +
                                    " values for a lattice of " + std::to_string(l.num_points()) + " points");
}

/// In-place cubic B-spline interpolation prefilter of one line c[0], c[stride], ...
/// (n >= 2): gain 6, causal then anti-causal recursion with pole z, mirror boundary.
void cubic_bspline_prefilter_line(double* c, int64_t n, int64_t stride) {
    const double z = std::sqrt(3.0) - 2.0;
    auto at = [&](int64_t k) -> double& { return c[k * stride]; };
    for (int64_t k = 0; k < n; ++k) at(k) *= 6.0;
    // Causal initial value: sum_k z^k c~[k] over one period of the mirrored sequence
    double z1 = z, zn = std::pow(z, double(n - 1));
    double sum = at(0) + zn * at(n - 1);
    zn *= zn / z;
    for (int64_t k = 1; k < n - 1; ++k) {
        sum += (z1 + zn) * at(k);
        z1 *= z;
        zn /= z;
    }
    at(0) = sum / (1.0 - z1 * z1);
    for (int64_t k = 1; k < n; ++k) at(k) += z * at(k - 1);
    // Anti-causal initial value, then the anti-causal recursion
    at(n - 1) = (z / (z * z - 1.0)) * (z * at(n - 2) + at(n - 1));
    for (int64_t k = n - 2; k >= 0; --k) at(k) = z * (at(k + 1) - at(k));
}

double max_abs(const std::vector<double>& v) {
    double m = 0;
    for (double x : v) m = std::max(m, std::abs(x));
    return m;
}

/// Chebyshev iteration for A c = f with A's spectrum in [lo, hi] (Saad, "Iterative methods
/// for sparse linear systems", 2nd ed., Algorithm 12.1).
std::vector<double> solve_bcc_interpolation(const Lattice& l, const std::vector<double>& f, int threads,
                                            BccSolveReport* report) {
    const double a0 = kBccBoxQuinticPhi0, a1 = kBccBoxQuinticPhi1, a2 = kBccBoxQuinticPhi2;
    const double lo = 0.2, hi = 1.0, theta = (hi + lo) / 2, delta = (hi - lo) / 2, sigma = theta / delta;
    const size_t n = f.size();
    const double target = 1e-13 * max_abs(f);
    std::vector<double> c(n, 0.0), r = f, d(n), ad(n);
    for (size_t i = 0; i < n; ++i) d[i] = r[i] / theta;
    double rho = 1 / sigma;
    int it = 0;
    for (; it < 200; ++it) {
        apply_bcc_stencil(l, d.data(), ad.data(), a0, a1, a2, threads);
        double worst = 0;
        for (size_t i = 0; i < n; ++i) {
            c[i] += d[i];
            r[i] -= ad[i];
            worst = std::max(worst, std::abs(r[i]));
        }
        if (worst <= 0.25 * target) break;
        const double rho_next = 1 / (2 * sigma - rho);
        for (size_t i = 0; i < n; ++i) d[i] = rho_next * rho * d[i] + 2 * rho_next / delta * r[i];
        rho = rho_next;
    }
    // The recursive residual drifts from the true one by rounding: recompute it
    apply_bcc_stencil(l, c.data(), ad.data(), a0, a1, a2, threads);
    double residual = 0;
    for (size_t i = 0; i < n; ++i) residual = std::max(residual, std::abs(f[i] - ad[i]));
    const double scale = std::max(max_abs(f), 1e-300);
    if (report) *report = {it + 1, residual / scale};
    if (residual > 10 * target && residual > 1e-300)
        throw std::runtime_error("bcc_box_quintic interpolation prefilter: relative residual " +
                                 std::to_string(residual / scale) + " after " + std::to_string(it + 1) +
                                 " iterations; expected <= 1e-12");
    return c;
}

}  // namespace

void apply_bcc_stencil(const Lattice& l, const double* in, double* out, double w_centre, double w_diagonal,
                       double w_axis, int threads) {
    const Int3 top{2 * l.resolution.x - 2, 2 * l.resolution.y - 2, 2 * l.resolution.z - 2};
    auto value = [&](const Int3& c) {
        const Int3 m{mirror_coordinate(c.x, top.x), mirror_coordinate(c.y, top.y), mirror_coordinate(c.z, top.z)};
        return in[bcc_index(l, m)];
    };
    parallel_for(l.num_points(), kChunk, threads, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) {
            const Int3 c = l.coords_of(i);
            double diagonal = 0, axis = 0;
            for (int k = 1; k <= 8; ++k) {
                const Int3 o = bcc_neighbour_offset(k);
                diagonal += value({c.x + o.x, c.y + o.y, c.z + o.z});
            }
            if (w_axis != 0)
                for (int k = 9; k <= 14; ++k) {
                    const Int3 o = bcc_neighbour_offset(k);
                    axis += value({c.x + o.x, c.y + o.y, c.z + o.z});
                }
            out[i] = w_centre * in[i] + w_diagonal * diagonal + w_axis * axis;
        }
    });
}

std::vector<double> cc_bspline3_coefficients(const Lattice& l, const std::vector<double>& values, int threads) {
    check_values(l, values, LatticeType::CC, 2, "cc_bspline3");
    std::vector<double> c = values;
    const Int3 r = l.resolution;
    const int64_t stride[3] = {1, r.x, int64_t(r.x) * r.y};
    // One pass per axis over every line along it
    for (int axis = 0; axis < 3; ++axis) {
        const int a = (axis + 1) % 3, b = (axis + 2) % 3;
        const int64_t lines = int64_t(r[a]) * r[b];
        parallel_for(lines, 64, threads, [&](int64_t begin, int64_t end) {
            for (int64_t line = begin; line < end; ++line) {
                const int64_t start = (line % r[a]) * stride[a] + (line / r[a]) * stride[b];
                cubic_bspline_prefilter_line(c.data() + start, r[axis], stride[axis]);
            }
        });
    }
    return c;
}

std::vector<double> bcc_box_quintic_coefficients(const Lattice& l, const std::vector<double>& values,
                                                 SplinePrefilter prefilter, int threads, BccSolveReport* report) {
    check_values(l, values, LatticeType::BCC, 4, "bcc_box_quintic");
    if (prefilter == SplinePrefilter::Interpolation) return solve_bcc_interpolation(l, values, threads, report);
    if (prefilter != SplinePrefilter::QuasiInterpolation)
        throw std::invalid_argument("bcc_box_quintic prefilter: expected quasi-interpolation or interpolation");
    std::vector<double> c(values.size());
    apply_bcc_stencil(l, values.data(), c.data(), 5.0 / 3.0, -1.0 / 12.0, 0.0, threads);
    return c;
}

void build_spline_coefficients(HermiteData<double>& d, SplinePrefilter prefilter, int threads) {
    if (prefilter == SplinePrefilter::None) return;
    if (d.lattice.type == LatticeType::CC && prefilter != SplinePrefilter::Interpolation)
        throw std::invalid_argument("cc_bspline3 prefilter: only interpolation is provided on CC");
    d.higher = d.lattice.type == LatticeType::CC ? cc_bspline3_coefficients(d.lattice, d.values, threads)
                                                 : bcc_box_quintic_coefficients(d.lattice, d.values, prefilter, threads);
    d.higher_stride = 1;
}

}  // namespace sdf
