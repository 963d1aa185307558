#include "core/reconstruction/hermite_data.h"
#include "core/reconstruction/spline_prefilters.h"

#include "core/parallel/parallel_for.h"
#include "core/reconstruction/bcc_cubic_tables.h"
#include "core/reconstruction/bcc_least_squares.h"
#include "kernels/reconstruction/bcc_stencils.h"
#include "kernels/reconstruction/cc_finite_differences.h"

namespace sdf {
namespace {

constexpr int64_t kChunk = 4096;

/// Runs fn(index) for every lattice point on `threads` threads.
template <typename F>
void for_each_point(int64_t n, int threads, const F& fn) {
    parallel_for(n, kChunk, threads, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i) fn(i);
    });
}

/// CC grid indices (i, j, k) of a storage index (Lattice::coords_of is in units of h/2).
Int3 cc_grid_point(const Lattice& l, int64_t index) {
    const Int3 c = l.coords_of(index);
    return {c.x / 2, c.y / 2, c.z / 2};
}

/// True gradients (world units) as derivatives per lattice unit.
std::vector<Vec3d> scaled_gradients(const SampledField& field, double unit) {
    std::vector<Vec3d> g(field.gradient.size());
    for (size_t i = 0; i < g.size(); ++i) g[i] = field.gradient[i] * unit;
    return g;
}

void build_cc_tricubic(HermiteData<double>& d, const SampledField& field, const ReconstructionSpec& spec, double unit) {
    const int64_t n = field.size();
    const bool true_first = spec.derivatives == DerivativeSource::True;
    const std::vector<Vec3d> g = true_first ? scaled_gradients(field, unit) : std::vector<Vec3d>();
    d.first.resize(size_t(n));
    d.higher.resize(size_t(n) * kCcHigherStride);
    for_each_point(n, spec.threads, [&](int64_t i) {
        const Int3 p = cc_grid_point(d.lattice, i);
        const CcHermitePoint<double> h = true_first ? cc_hermite_from_gradients(d.lattice, g.data(), p)
                                                    : cc_hermite_from_values(d.lattice, d.values.data(), p);
        d.first[size_t(i)] = h.first;
        for (int k = 0; k < kCcHigherStride; ++k) d.higher[size_t(i) * kCcHigherStride + k] = h.higher[k];
    });
}

void build_bcc_cubic(HermiteData<double>& d, const SampledField& field, const ReconstructionSpec& spec, double unit) {
    const int64_t n = field.size();
    const bool true_first = spec.derivatives == DerivativeSource::True;
    const std::vector<BccLeastSquaresFit<double>> fits = bcc_least_squares_fits<double>(stencil_weighting(spec));
    const int stride = d.higher_stride;
    d.first.resize(size_t(n));
    d.higher.resize(size_t(n) * size_t(stride));
    for_each_point(n, spec.threads, [&](int64_t i) {
        const CubicJet<double> jet = bcc_least_squares_jet(fits.data(), d.lattice, d.values.data(), d.lattice.coords_of(i));
        d.first[size_t(i)] = true_first ? field.gradient[size_t(i)] * unit : jet.gradient;
        double* h = d.higher.data() + size_t(i) * size_t(stride);
        h[kBccDxy] = jet.hessian.xy;
        h[kBccDxz] = jet.hessian.xz;
        h[kBccDyz] = jet.hessian.yz;
        if (stride >= kBccFullStride) {
            h[kBccDxx] = jet.hessian.xx;
            h[kBccDyy] = jet.hessian.yy;
            h[kBccDzz] = jet.hessian.zz;
        }
    });
    d.faces = to_face_table<double>(interpolator_point_data(spec.interpolator) == PointData::BccCubicC0Jet
                                        ? bcc_cubic_c0_face_weights()
                                        : bcc_cubic_face_weights());
}

}  // namespace

template <typename T>
LatticeFieldView<T> HermiteData<T>::view() const {
    LatticeFieldView<T> v;
    v.lattice = lattice;
    v.origin = Vec3<T>(lattice.origin);
    const double unit = lattice.type == LatticeType::CC ? lattice.spacing : lattice.half_spacing();
    v.unit = T(unit);
    v.inv_unit = T(1.0 / unit);
    v.values = values.data();
    v.first = first.empty() ? nullptr : first.data();
    v.higher = higher.empty() ? nullptr : higher.data();
    v.higher_stride = higher_stride;
    v.bcc_faces = faces;
    return v;
}

HermiteData<double> build_hermite_data(const SampledField& field, const ReconstructionSpec& spec) {
    const bool has_gradient = !field.gradient.empty();
    if (has_gradient && field.gradient.size() != field.distance.size())
        throw std::invalid_argument("field has " + std::to_string(field.gradient.size()) + " gradients for " +
                                    std::to_string(field.distance.size()) + " values");
    if (field.size() != field.lattice.num_points())
        throw std::invalid_argument("field has " + std::to_string(field.size()) + " values; its lattice has " +
                                    std::to_string(field.lattice.num_points()) + " points");
    validate_reconstruction(spec, field.lattice, has_gradient);
    HermiteData<double> d;
    d.lattice = field.lattice;
    d.values = field.distance;
    d.higher_stride = interpolator_higher_stride(spec.interpolator);
    const double unit = field.lattice.type == LatticeType::CC ? field.lattice.spacing : field.lattice.half_spacing();
    switch (interpolator_point_data(spec.interpolator)) {
        case PointData::Values: break;
        case PointData::CcTricubicJet: build_cc_tricubic(d, field, spec, unit); break;
        case PointData::BccCubicJet:
        case PointData::BccCubicC0Jet: build_bcc_cubic(d, field, spec, unit); break;
        case PointData::SplineInterpolation:
            build_spline_coefficients(d, SplinePrefilter::Interpolation, spec.threads);
            break;
        case PointData::SplineQuasiInterpolation:
            build_spline_coefficients(d, SplinePrefilter::QuasiInterpolation, spec.threads);
            break;
    }
    return d;
}

template <typename T>
HermiteData<T> convert_hermite_data(const HermiteData<double>& d) {
    HermiteData<T> out;
    out.lattice = d.lattice;
    out.values.assign(d.values.begin(), d.values.end());
    out.first.reserve(d.first.size());
    for (const Vec3d& g : d.first) out.first.emplace_back(g);
    out.higher.assign(d.higher.begin(), d.higher.end());
    out.higher_stride = d.higher_stride;
    for (int l = 0; l < 4; ++l)
        for (int v = 0; v < 4; ++v)
            for (int k = 0; k < kBccData; ++k) out.faces.w[v][k][l] = T(d.faces.w[v][k][l]);
    return out;
}

template struct HermiteData<float>;
template struct HermiteData<double>;
template HermiteData<float> convert_hermite_data<float>(const HermiteData<double>&);
template HermiteData<double> convert_hermite_data<double>(const HermiteData<double>&);

}  // namespace sdf
