/// @file reconstruction_spec.h
/// @brief What a reconstruction is made of: an interpolator (by config name), the source of
/// its derivative data, and the checks that reject meaningless combinations.
///
/// Interpolators: every filter of the one table, AllInterpolators in
/// kernels/reconstruction/interpolators.h (interpolator_names(); `sdf-eval --help` lists
/// them). The derivative sources a filter accepts follow from its static interface
/// (valid_derivative_sources):
///   a filter that reads no derivative data (uses_first() false: trilinear, bcc_linear, the
///     box splines, ...): "fd" only (for catmull_rom it names the implied central
///     differences). "true" and "fd_weighted" are rejected.
///   a CC filter that reads derivatives: "true" or "fd". tricubic_lm: "true" = fx, fy, fz
///     from the sampled gradients, fxy, fxz, fyz, fxyz from central differences of those
///     gradients; "fd" = all 7 derivatives by central differences of the values
///     (cc_finite_differences.h; equals catmull_rom). "fd_weighted" is rejected: the
///     Gaussian weighting belongs to the BCC least-squares fit.
///   a BCC filter that reads derivatives: "true", "fd" or "fd_weighted". bcc_cubic,
///     bcc_cubic_c0: "true" = first derivatives from the sampled gradients, second
///     derivatives from the plain 27-point least-squares fit; "fd" = all from the plain fit;
///     "fd_weighted" = all from the Gaussian-weighted fit (eq. 4-15; at interior points the
///     first derivatives are the same as "fd", only the second ones change).
#pragma once

#include <string>
#include <vector>

#include "core/reconstruction/stencil_weighting.h"
#include "kernels/reconstruction/interpolators.h"

namespace sdf {

enum class DerivativeSource { True, FiniteDifferences, FiniteDifferencesWeighted };

struct ReconstructionSpec {
    InterpolatorKind interpolator = kind_of<Trilinear>();
    DerivativeSource derivatives = DerivativeSource::FiniteDifferences;
    /// fd_weighted only: sigma^2 of eq. 4-15 and its unit (bcc_least_squares.h).
    double sigma2 = 0.5;
    SigmaUnits sigma_units = SigmaUnits::LatticeUnits;
    int threads = 0;  ///< for building the derivative arrays; 0 = all hardware threads
};

const char* interpolator_name(InterpolatorKind kind);
const char* derivative_source_name(DerivativeSource source);
std::vector<std::string> interpolator_names();

/// The names by lattice, for the tools' help: "trilinear, ... (CC); bcc_linear, ... (BCC)".
std::string interpolator_help();

/// Parse config names; unknown names throw std::invalid_argument listing the valid ones.
InterpolatorKind parse_interpolator(const std::string& name);
DerivativeSource parse_derivative_source(const std::string& name);

LatticeType interpolator_lattice(InterpolatorKind kind);
bool interpolator_uses_first(InterpolatorKind kind);
int interpolator_higher_stride(InterpolatorKind kind);
PointData interpolator_point_data(InterpolatorKind kind);

/// The derivative sources that `kind` accepts.
std::vector<DerivativeSource> valid_derivative_sources(InterpolatorKind kind);

/// "true" when the interpolator uses first derivatives and the field has gradients, else "fd".
DerivativeSource default_derivative_source(InterpolatorKind kind, bool field_has_gradient);

/// The weighting the spec's derivative source implies for the BCC fit.
StencilWeighting stencil_weighting(const ReconstructionSpec& spec);

/// Throws std::invalid_argument (with what was seen and what is expected) when the spec does
/// not fit the lattice or the field's channels.
void validate_reconstruction(const ReconstructionSpec& spec, const Lattice& lattice, bool field_has_gradient);

/// "bcc_cubic/fd_weighted (sigma^2 = 0.5 lattice_units)".
std::string describe(const ReconstructionSpec& spec);

}  // namespace sdf
