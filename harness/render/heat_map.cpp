#include "harness/render/heat_map.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "core/raycast/image_metrics.h"

namespace sdf {

void viridis(float t, float rgb[3]) {
    static const float table[9][3] = {{0.267f, 0.005f, 0.329f}, {0.279f, 0.175f, 0.483f}, {0.230f, 0.322f, 0.546f},
                                      {0.173f, 0.449f, 0.558f}, {0.128f, 0.567f, 0.551f}, {0.135f, 0.659f, 0.518f},
                                      {0.267f, 0.749f, 0.441f}, {0.478f, 0.821f, 0.318f}, {0.993f, 0.906f, 0.144f}};
    t = std::clamp(t, 0.0f, 1.0f) * 8.0f;
    const int i = std::min(7, int(t));
    const float f = t - float(i);
    for (int c = 0; c < 3; ++c) rgb[c] = table[i][c] * (1 - f) + table[i + 1][c] * f;
}

ImageRgb normal_error_heat_map(const RenderedImage& test, const RenderedImage& reference, double max_degrees) {
    if (test.width != reference.width || test.height != reference.height)
        throw std::invalid_argument("normal_error_heat_map: sizes differ");
    if (!(max_degrees > 0))
        throw std::invalid_argument("normal_error_heat_map: max_degrees must be positive, got " +
                                    std::to_string(max_degrees));
    ImageRgb out(test.width, test.height, 1.0f);
    for (int y = 0; y < test.height; ++y)
        for (int x = 0; x < test.width; ++x) {
            const PixelRecord& a = test.at(x, y);
            const PixelRecord& b = reference.at(x, y);
            if (a.is_hit() && b.is_hit()) {
                float rgb[3];
                viridis(float(angle_degrees(a.normal, b.normal) / max_degrees), rgb);
                out.set(x, y, rgb[0], rgb[1], rgb[2]);
            } else if (a.is_hit() != b.is_hit()) {
                out.set(x, y, 1.0f, 0.0f, 1.0f);
            }
        }
    return out;
}

ImageRgb viridis_bar(int width, int height) {
    ImageRgb out(width, height);
    for (int x = 0; x < width; ++x) {
        float rgb[3];
        viridis(width > 1 ? float(x) / float(width - 1) : 0.0f, rgb);
        for (int y = 0; y < height; ++y) out.set(x, y, rgb[0], rgb[1], rgb[2]);
    }
    return out;
}

ImageRgb colour_bar_with_ticks(int width, int bar_height, int ticks, int text_band) {
    const int mark = std::max(3, bar_height / 3);
    ImageRgb out(width, bar_height + mark + text_band, 1.0f);
    blit(out, viridis_bar(width, bar_height), 0, 0);
    for (int t = 0; t <= ticks; ++t) {
        const int x = ticks > 0 ? int(double(t) * (width - 1) / ticks + 0.5) : 0;
        for (int y = 0; y < bar_height + mark; ++y) {
            if (y < bar_height && t > 0 && t < ticks) continue;  // inner marks below the bar only
            out.set(x, y, 0.0f, 0.0f, 0.0f);
        }
    }
    return out;
}

}  // namespace sdf
