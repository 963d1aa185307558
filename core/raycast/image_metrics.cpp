#include "core/raycast/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sdf {

double angle_degrees(const Vec3f& a, const Vec3f& b) {
    // atan2(|a x b|, a.b): accurate for small angles (acos is not) and exactly 0 for a == b
    const Vec3d u(a), v(b);
    return std::atan2(length(cross(u, v)), dot(u, v)) * 180.0 / M_PI;
}

ErrorSummary summarize_errors(std::vector<double>& values) {
    ErrorSummary s;
    if (values.empty()) return s;
    double sum = 0;
    for (double v : values) sum += v;
    s.mean = sum / double(values.size());
    // Nearest rank: the smallest value with at least 95% of the values at or below it
    const size_t rank = size_t(std::ceil(0.95 * double(values.size())));
    std::nth_element(values.begin(), values.begin() + long(rank - 1), values.end());
    s.p95 = values[rank - 1];
    s.max = *std::max_element(values.begin(), values.end());
    return s;
}

ImageMetrics compare_images(const RenderedImage& test, const RenderedImage& reference, double length_unit) {
    if (test.width != reference.width || test.height != reference.height)
        throw std::invalid_argument("compare_images: sizes differ: test " + std::to_string(test.width) + "x" +
                                    std::to_string(test.height) + ", reference " + std::to_string(reference.width) +
                                    "x" + std::to_string(reference.height));
    ImageMetrics m;
    m.pixels = int64_t(test.pixels.size());
    m.length_unit = length_unit;
    std::vector<double> angles, depths;
    double squared = 0;
    for (size_t i = 0; i < test.pixels.size(); ++i) {
        const PixelRecord& a = test.pixels[i];
        const PixelRecord& b = reference.pixels[i];
        const double ds = double(a.shade) - double(b.shade);
        squared += ds * ds;
        m.hit_test += a.is_hit() ? 1 : 0;
        m.hit_reference += b.is_hit() ? 1 : 0;
        if (a.is_hit() && b.is_hit()) {
            ++m.hit_both;
            angles.push_back(angle_degrees(a.normal, b.normal));
            depths.push_back(std::abs(double(a.depth) - double(b.depth)));
        } else if (a.is_hit()) {
            ++m.only_test;
        } else if (b.is_hit()) {
            ++m.only_reference;
        }
    }
    m.coverage_mismatch = m.only_test + m.only_reference;
    m.coverage_mismatch_fraction = m.pixels > 0 ? double(m.coverage_mismatch) / double(m.pixels) : 0.0;
    m.shade_rmse = m.pixels > 0 ? std::sqrt(squared / double(m.pixels)) : 0.0;
    m.normal_angle_degrees = summarize_errors(angles);
    if (length_unit > 0) {
        std::vector<double> scaled(depths);
        for (double& d : scaled) d /= length_unit;
        m.depth_in_units = summarize_errors(scaled);
    }
    m.depth = summarize_errors(depths);
    return m;
}

nlohmann::json metrics_to_json(const ImageMetrics& m) {
    auto summary = [](const ErrorSummary& s) { return nlohmann::json{{"mean", s.mean}, {"p95", s.p95}, {"max", s.max}}; };
    nlohmann::json j = {{"pixels", m.pixels},
                        {"hit_test", m.hit_test},
                        {"hit_reference", m.hit_reference},
                        {"hit_both", m.hit_both},
                        {"only_test", m.only_test},
                        {"only_reference", m.only_reference},
                        {"coverage_mismatch", m.coverage_mismatch},
                        {"coverage_mismatch_fraction", m.coverage_mismatch_fraction},
                        {"normal_angle_degrees", summary(m.normal_angle_degrees)},
                        {"depth_world", summary(m.depth)},
                        {"shade_rmse", m.shade_rmse}};
    if (m.length_unit > 0) {
        j["length_unit"] = m.length_unit;
        j["depth_in_length_units"] = summary(m.depth_in_units);
    }
    return j;
}

}  // namespace sdf
