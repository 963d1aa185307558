#include "core/sampling/narrow_band.h"

#include <stdexcept>
#include <string>

namespace sdf {

void require_band_width(double w, const std::string& what) {
    if (!(w >= 0) || !std::isfinite(w))
        throw std::invalid_argument(what + ": expected a finite band width >= 0 in mesh units (0: no band), got " +
                                    std::to_string(w));
}

NarrowBandCounts apply_narrow_band(SampledField& field, double w) {
    require_band_width(w);
    if (field.closest_triangle.size() != field.distance.size())  // it marks the band's points
        throw std::invalid_argument("narrow band: the field holds " + std::to_string(field.closest_triangle.size()) +
                                    " closest triangles for " + std::to_string(field.distance.size()) +
                                    " points; banding needs one per point");
    NarrowBandCounts counts;
    for (int64_t i = 0; i < field.size(); ++i) {
        if (field.closest_triangle[size_t(i)] == kOutsideBandTriangle) {
            ++counts.outside;
        } else if (outside_band(field.distance[size_t(i)], w)) {
            store_outside_band(field, i, std::signbit(field.distance[size_t(i)]), w);
            ++counts.outside;
        } else {
            ++counts.in_band;
        }
    }
    return counts;
}

NarrowBandCounts count_narrow_band(const SampledField& field) {
    NarrowBandCounts counts;
    for (int32_t t : field.closest_triangle) (t == kOutsideBandTriangle ? counts.outside : counts.in_band) += 1;
    return counts;
}

BandReport narrow_band_provenance(double w, const NarrowBandCounts& counts, const std::string& how) {
    BandReport b;
    b.width = w;
    b.points_in_band = counts.in_band;
    b.points_outside = counts.outside;
    b.how = how;
    return b;
}

}  // namespace sdf
