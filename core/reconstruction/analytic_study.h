/// @file analytic_study.h
/// @brief Reconstruction of analytic functions: sample a function (value + exact gradient)
/// on a CC or BCC lattice, reconstruct it, and measure the error at a dense probe grid
/// against the function itself. This is the experiment behind the thesis's Table 4-1 ML row
/// (Marschner-Lobb on a 111 x 111 x 222 BCC lattice over [-1,1]^3, bcc_cubic with plain
/// and Gaussian-weighted least-squares derivatives); the harness's "analytic" experiment
/// kind is meant to call run_analytic_study().
///
/// Error figures: e = reconstructed - exact at every probe, in the function's own units
/// (ML values lie in [0,1]). Reported: RMS, max |e|, mean |e|, the L2 norm sqrt(sum e^2),
/// and RMS and L2 norm scaled by 255 (8-bit data units, as the thesis's volume datasets).
/// A margin of 2h keeps the probes where every vertex of the containing tetrahedron has a
/// complete, centred 27-point neighbourhood (no boundary extrapolation in the derivatives).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "core/reconstruction/reconstruction.h"
#include "kernels/reconstruction/analytic_functions.h"

namespace sdf {

/// Analytic functions by name: "marschner_lobb" (f_M = 6, alpha = 0.25), "trig"
/// (TrigFunction, scale 1). Throws std::invalid_argument for other names.
AnalyticSample<double> evaluate_analytic(const std::string& function, const Vec3d& p);

/// A field whose values and gradients are f and grad f at the lattice points.
template <typename F>
SampledField sample_analytic_field(const Lattice& lattice, const F& f) {
    SampledField field;
    field.lattice = lattice;
    field.precision = Precision::Double;
    field.resize(lattice.num_points());
    field.closest_triangle.clear();
    for (int64_t i = 0; i < field.size(); ++i) {
        const AnalyticSample<double> s = f(lattice.position(i));
        field.distance[size_t(i)] = s.value;
        field.gradient[size_t(i)] = s.gradient;
    }
    return field;
}

/// The lattice whose primary grid spans [lo, hi] with `resolution` points per axis
/// (resolution = CC points, or the BCC primary grid: thesis 111x111x222 -> {111,111,111}).
Lattice lattice_spanning(LatticeType type, Int3 resolution, const Vec3d& lo, const Vec3d& hi);

struct AnalyticStudySpec {
    std::string function = "marschner_lobb";
    LatticeType lattice = LatticeType::BCC;
    Int3 resolution{111, 111, 111};
    Vec3d domain_min{-1, -1, -1}, domain_max{1, 1, 1};
    ReconstructionSpec reconstruction{kind_of<BccCubic>(), DerivativeSource::FiniteDifferences};
    int probes_per_axis = 256;  ///< probes at the cell centres of a regular grid over the box:
    double margin = 0;          ///< the interpolator's domain() shrunk by margin * h per side
    /// Extra lattice spacings beyond the box on every side (0: the lattice spans the box).
    /// The samples counted (lattice, lattice_points) are still those over the box; probes stay
    /// inside the box. Padding keeps a filter's boundary treatment (the prefilters' mirror
    /// extension) away from the probes, so that filters are compared on their interior error.
    int padding = 0;
    /// probes_per_axis^3 uniformly random probes in the probe box (a fixed counter-based
    /// sequence: the same points for every filter and thread count) instead of the cell
    /// centres. A regular probe grid whose spacing is commensurate with the lattice's sits at
    /// the same few offsets in every cell, and an interpolating filter's error there is not
    /// its mean: orders measured along a series of lattices then alternate.
    bool random_probes = false;
    int threads = 0;
};

struct AnalyticStudyResult {
    std::string description;
    std::string lattice;       ///< thesis notation, of the lattice over the box (without padding)
    int64_t lattice_points = 0;
    int padding = 0;           ///< spacings the sampled lattice extends beyond the box
    bool random_probes = false;
    int64_t probes = 0;
    double rms = 0, max_abs = 0, mean_abs = 0, l2_norm = 0;
    double rms_255 = 0, l2_norm_255 = 0;
    double gradient_rms = 0;   ///< RMS of |grad error|
    DomainBox<double> probe_box{};
    /// Cost (time_evaluation in reconstruction.h): building the reconstruction (derivative
    /// arrays or prefilter, on `threads`), and one thread's time per evaluation at up to 2^16
    /// probes spread evenly over the probe grid.
    double prepare_seconds = 0;
    double eval_ns_per_point = 0;
    int64_t timed_points = 0;
};

AnalyticStudyResult run_analytic_study(const AnalyticStudySpec& spec);

nlohmann::json to_json(const AnalyticStudyResult& r);

}  // namespace sdf
