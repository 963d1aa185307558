/// @file image_metrics.h
/// @brief How far a render is from a reference render of the same camera (normally the
/// mesh reference, mesh_reference.h): per-pixel normal angle error, depth error, coverage
/// mismatch and the RMSE of the shaded values (docs/raycast.md, "Image metrics").
///
/// Definitions (both images the same size; normals are the unit, viewer-facing shading
/// normals of the records):
///   both = pixels hit in both images; only_test / only_reference = hit in one only
///   normal angle error = the angle between n_test and n_ref in degrees (atan2 of the
///     cross and dot products: exact for equal vectors, accurate for small angles), over `both`:
///     mean, 95th percentile (nearest rank), max
///   depth error = |depth_test - depth_ref| in world units, over `both`: mean, 95th
///     percentile, max; and the same divided by `length_unit` when one is given (e.g. the
///     lattice spacing h)
///   coverage mismatch = only_test + only_reference, as a count and as a fraction of all
///     pixels
///   shade RMSE = sqrt(mean over all pixels of (shade_test - shade_ref)^2), background
///     included (a miss has the background value)
/// An image compared with itself gives zero for every error and mismatch.
#pragma once

#include <nlohmann/json.hpp>

#include "core/raycast/rendered_image.h"

namespace sdf {

struct ErrorSummary {
    double mean = 0, p95 = 0, max = 0;
};

struct ImageMetrics {
    int64_t pixels = 0;
    int64_t hit_test = 0, hit_reference = 0, hit_both = 0;
    int64_t only_test = 0, only_reference = 0;
    int64_t coverage_mismatch = 0;
    double coverage_mismatch_fraction = 0;
    ErrorSummary normal_angle_degrees;
    ErrorSummary depth;            ///< world units
    double length_unit = 0;        ///< 0 when no unit was given
    ErrorSummary depth_in_units;   ///< depth / length_unit
    double shade_rmse = 0;
};

/// Throws std::invalid_argument when the sizes differ.
ImageMetrics compare_images(const RenderedImage& test, const RenderedImage& reference, double length_unit = 0);

/// Mean, 95th percentile (nearest rank) and max of `values` (reordered); zeros when empty.
ErrorSummary summarize_errors(std::vector<double>& values);

nlohmann::json metrics_to_json(const ImageMetrics& m);

/// Angle in degrees between two vectors, atan2(|a x b|, a . b): 0 for equal vectors.
double angle_degrees(const Vec3f& a, const Vec3f& b);

}  // namespace sdf
