/// @file narrow_band.h
/// @brief The narrow band of SamplerOptions::band_width (issue 14): a point with
/// |d| <= w keeps its exact values; every other point gets distance +-w with the sign of its
/// exact distance, gradient (0,0,0) and closest_triangle kOutsideBandTriangle. The banded
/// field is a function of the exact field alone, so apply_narrow_band() on a full field is
/// the truth every banded sampler is tested against, and the fallback of samplers that
/// compute every point anyway (brute force: the band by post-processing).
#pragma once

#include <cmath>
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "core/sampling/sampled_field.h"

namespace sdf {

/// Throws std::invalid_argument naming `what` unless w is finite and >= 0 (0: no band).
void require_band_width(double w, const std::string& what = "band_width");

/// Whether a point whose exact signed distance is d lies outside the band of width w (> 0).
inline bool outside_band(double d, double w) { return w > 0 && !(std::abs(d) <= w); }

/// Stores the outside-band values at index i: distance -w when `negative` (inside), else +w.
inline void store_outside_band(SampledField& field, int64_t i, bool negative, double w) {
    field.distance[size_t(i)] = negative ? -w : w;
    field.gradient[size_t(i)] = Vec3d(0.0);
    field.closest_triangle[size_t(i)] = kOutsideBandTriangle;
}

struct NarrowBandCounts {
    int64_t in_band = 0;   ///< points holding exact values
    int64_t outside = 0;   ///< points flagged kOutsideBandTriangle
};

/// Applies the band rule of width w > 0 to every point of `field` (exact values in, banded
/// out); a point already flagged stays as it is, so applying it twice changes nothing.
/// Returns the counts. w = 0 leaves the field alone and counts every point as in the band.
NarrowBandCounts apply_narrow_band(SampledField& field, double w);

/// The counts of a banded field, without changing it.
NarrowBandCounts count_narrow_band(const SampledField& field);

/// The band of a field's sampler report (SamplerReport::band) of width w with these counts
/// (how: "bricks skipped by the distance bound" or "post-processed").
BandReport narrow_band_provenance(double w, const NarrowBandCounts& counts, const std::string& how);

}  // namespace sdf
