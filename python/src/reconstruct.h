/// @file reconstruct.h
/// @brief What Field.reconstruct and SparseField.reconstruct share: the spec of their keywords,
/// the evaluation of a points array as a task, and the (values, gradients) arrays with the
/// outside= rule of the lattice's edge.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/reconstruction/reconstruction_spec.h"
#include "python/src/common.h"

namespace sdf {

/// The spec of reconstruct()'s keywords: an empty `interpolator` is bcc_cubic on BCC,
/// tricubic_lm on CC; an empty `derivatives` sdf-eval's default (default_derivative_source).
ReconstructionSpec reconstruction_spec(LatticeType lattice, bool has_gradient, const std::string& interpolator,
                                       const std::string& derivatives, double sigma2, const std::string& sigma_units,
                                       int threads);

/// reconstruct()'s arrays (values (N,), gradients (N, 3)) of `samples` at `points`: a sample
/// outside `domain` is NaN (outside="nan"), as reconstructed (clamped into it: "clamp") or
/// raises ValueError naming the first such row ("error").
py::tuple reconstruction_arrays(const std::vector<Vec3d>& points, const std::vector<ReconstructedSample<double>>& samples,
                                const DomainBox<double>& domain, const std::string& outside);

/// Runs `evaluate()` (the reconstruction of the points of `array`, points_argument()'s) as a task,
/// turning an allocation failure into a MemoryError that names the points' size.
std::pair<std::vector<Vec3d>, std::vector<ReconstructedSample<double>>> reconstruct_points(
    const DoubleArray& array, const std::function<std::vector<ReconstructedSample<double>>(const std::vector<Vec3d>&)>& evaluate);

}  // namespace sdf
