/// @file reconstruction.h
/// @brief The host-side reconstruction: a sampled field, an interpolator and a derivative
/// source, built once, then evaluated (value + world gradient) at arbitrary points, one at a
/// time or in batches on the CPU thread pool.
///
///   Reconstruction r(field, "bcc_cubic", "fd");
///   ReconstructedSample<double> s = r.evaluate({0.1, 0.2, 0.3});
///
/// Points outside domain() are clamped into it and flagged inside = false
/// (kernels/reconstruction/interpolator.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/reconstruction/hermite_data.h"

namespace sdf {

class Reconstruction {
public:
    /// Throws std::invalid_argument for a spec that does not fit the field.
    Reconstruction(const SampledField& field, const ReconstructionSpec& spec);
    /// By config names; an empty `derivatives` picks default_derivative_source().
    Reconstruction(const SampledField& field, const std::string& interpolator, const std::string& derivatives);

    const ReconstructionSpec& spec() const { return spec_; }
    std::string description() const { return describe(spec_); }
    const HermiteData<double>& data() const { return *data_; }
    const LatticeFieldView<double>& view() const { return view_; }
    DomainBox<double> domain() const;

    ReconstructedSample<double> evaluate(const Vec3d& p) const;
    /// out[i] = evaluate(points[i]); threads = 0 uses every hardware thread.
    void evaluate(const Vec3d* points, ReconstructedSample<double>* out, int64_t n, int threads = 0) const;
    std::vector<ReconstructedSample<double>> evaluate(const std::vector<Vec3d>& points, int threads = 0) const;

private:
    ReconstructionSpec spec_;
    std::unique_ptr<HermiteData<double>> data_;  // on the heap, so view_ survives moves
    LatticeFieldView<double> view_;
};

/// Evaluation speed as the studies record it: one thread, double, value + gradient, through
/// the batched evaluate() (one dispatch per batch, as the studies evaluate), at the first
/// min(points.size(), max_points) points in their given order, in chunks of 1024 points
/// whose fastest of `repetitions` passes count, so that a loaded machine's interruptions
/// count less (the figure is the filter's uncontended cost). Speed is recorded, never
/// asserted.
struct EvaluationTiming {
    double ns_per_point = 0;
    int64_t points = 0;
    int repetitions = 0;
};
EvaluationTiming time_evaluation(const Reconstruction& recon, const std::vector<Vec3d>& points,
                                 int64_t max_points = int64_t(1) << 16, int repetitions = 5);

}  // namespace sdf
