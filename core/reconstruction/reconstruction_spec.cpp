#include "core/reconstruction/reconstruction_spec.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "core/lattice/lattice_fitting.h"

namespace sdf {
namespace {

std::string joined(const std::vector<std::string>& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

std::string source_names(const std::vector<DerivativeSource>& sources) {
    std::vector<std::string> names;
    for (DerivativeSource s : sources) names.emplace_back(derivative_source_name(s));
    return joined(names);
}

/// Smallest resolution per axis the interpolator needs (its support, and for the BCC cubics
/// the 27-point fit of their derivative data).
int minimum_resolution(const ReconstructionSpec& spec) {
    return visit_interpolator(spec.interpolator, [](auto interp) { return decltype(interp)::min_resolution(); });
}

}  // namespace

const char* interpolator_name(InterpolatorKind kind) {
    return visit_interpolator(kind, [](auto interp) { return decltype(interp)::name(); });
}

const char* derivative_source_name(DerivativeSource source) {
    switch (source) {
        case DerivativeSource::True: return "true";
        case DerivativeSource::FiniteDifferences: return "fd";
        default: return "fd_weighted";
    }
}

std::vector<std::string> interpolator_names() {
    std::vector<std::string> names;
    for_each_interpolator([&](auto interp) { names.emplace_back(decltype(interp)::name()); });
    return names;
}

std::string interpolator_help() {
    std::string help;
    for (const LatticeKind& kind : kLatticeKinds) {
        std::string list;
        for_each_interpolator([&](auto interp) {
            using I = decltype(interp);
            if (I::lattice_type() == kind.type) list += (list.empty() ? "" : ", ") + std::string(I::name());
        });
        if (!list.empty()) help += (help.empty() ? "" : "; ") + list + " (" + kind.label + ")";
    }
    return help;
}

InterpolatorKind parse_interpolator(const std::string& name) {
    for (int k = 0; k < kInterpolatorKinds; ++k)
        if (name == interpolator_name(InterpolatorKind(k))) return InterpolatorKind(k);
    throw std::invalid_argument("unknown interpolator '" + name + "'; expected one of: " + joined(interpolator_names()));
}

DerivativeSource parse_derivative_source(const std::string& name) {
    for (DerivativeSource s : {DerivativeSource::True, DerivativeSource::FiniteDifferences,
                               DerivativeSource::FiniteDifferencesWeighted})
        if (name == derivative_source_name(s)) return s;
    throw std::invalid_argument("unknown derivative source '" + name + "'; expected one of: true, fd, fd_weighted");
}

LatticeType interpolator_lattice(InterpolatorKind kind) {
    return visit_interpolator(kind, [](auto interp) { return decltype(interp)::lattice_type(); });
}

bool interpolator_uses_first(InterpolatorKind kind) {
    return visit_interpolator(kind, [](auto interp) { return decltype(interp)::uses_first(); });
}

PointData interpolator_point_data(InterpolatorKind kind) {
    return visit_interpolator(kind, [](auto interp) { return decltype(interp)::point_data(); });
}

int interpolator_higher_stride(InterpolatorKind kind) {
    return visit_interpolator(kind, [](auto interp) { return decltype(interp)::higher_stride(); });
}

std::vector<DerivativeSource> valid_derivative_sources(InterpolatorKind kind) {
    if (!interpolator_uses_first(kind)) return {DerivativeSource::FiniteDifferences};
    if (interpolator_lattice(kind) == LatticeType::CC) return {DerivativeSource::True, DerivativeSource::FiniteDifferences};
    return {DerivativeSource::True, DerivativeSource::FiniteDifferences, DerivativeSource::FiniteDifferencesWeighted};
}

DerivativeSource default_derivative_source(InterpolatorKind kind, bool field_has_gradient) {
    return interpolator_uses_first(kind) && field_has_gradient ? DerivativeSource::True : DerivativeSource::FiniteDifferences;
}

StencilWeighting stencil_weighting(const ReconstructionSpec& spec) {
    StencilWeighting w;
    w.gaussian = spec.derivatives == DerivativeSource::FiniteDifferencesWeighted;
    w.sigma2 = spec.sigma2;
    w.units = spec.sigma_units;
    return w;
}

void validate_reconstruction(const ReconstructionSpec& spec, const Lattice& lattice, bool field_has_gradient) {
    const std::string name = interpolator_name(spec.interpolator);
    const LatticeType needed = interpolator_lattice(spec.interpolator);
    if (lattice.type != needed)
        throw std::invalid_argument("interpolator '" + name + "' needs a " + lattice_type_label(needed) +
                                    " field; this field is " + lattice_type_label(lattice.type) + " (" +
                                    lattice_notation(lattice) + ")");
    const auto valid = valid_derivative_sources(spec.interpolator);
    if (std::find(valid.begin(), valid.end(), spec.derivatives) == valid.end()) {
        std::string why = !interpolator_uses_first(spec.interpolator)
                              ? " (it reads no derivative data: its gradient is the derivative of the interpolant)"
                              : " (the Gaussian-weighted fit of thesis eq. 4-15 is defined on the BCC 27-point "
                                "neighbourhood only)";
        throw std::invalid_argument("interpolator '" + name + "' does not accept derivatives '" +
                                    derivative_source_name(spec.derivatives) + "'" + why + "; expected " +
                                    source_names(valid));
    }
    if (spec.derivatives == DerivativeSource::True && !field_has_gradient)
        throw std::invalid_argument("derivatives 'true' need the field's gradient channel, and this field has none; use "
                                    "'fd' or write the gradient channel (docs/field-format.md)");
    const int need = minimum_resolution(spec);
    for (int a = 0; a < 3; ++a)
        if (lattice.resolution[a] < need)
            throw std::invalid_argument("interpolator '" + name + "' with derivatives '" +
                                        derivative_source_name(spec.derivatives) + "' needs at least " +
                                        std::to_string(need) + " primary points per axis; this lattice is " +
                                        lattice_notation(lattice));
    if (spec.derivatives == DerivativeSource::FiniteDifferencesWeighted && !(spec.sigma2 > 0))
        throw std::invalid_argument("fd_weighted: sigma^2 must be positive, got " + std::to_string(spec.sigma2));
}

std::string describe(const ReconstructionSpec& spec) {
    std::ostringstream s;
    s << interpolator_name(spec.interpolator) << "/" << derivative_source_name(spec.derivatives);
    if (spec.derivatives == DerivativeSource::FiniteDifferencesWeighted)
        s << " (sigma^2 = " << spec.sigma2 << " " << sigma_units_name(spec.sigma_units) << ")";
    return s.str();
}

}  // namespace sdf
