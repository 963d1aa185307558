#include "harness/render/image_buffer.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace sdf {

ImageRgb shaded_image(const RenderedImage& image) {
    ImageRgb out(image.width, image.height);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const float s = image.at(x, y).shade;
            out.set(x, y, s, s, s);
        }
    return out;
}

ImageRgb downsample(const ImageRgb& image, int factor) {
    if (factor < 1) throw std::invalid_argument("downsample: factor must be >= 1, got " + std::to_string(factor));
    if (factor == 1) return image;
    ImageRgb out((image.width + factor - 1) / factor, (image.height + factor - 1) / factor);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            float sum[3] = {0, 0, 0};
            int n = 0;
            for (int j = y * factor; j < std::min(image.height, (y + 1) * factor); ++j)
                for (int i = x * factor; i < std::min(image.width, (x + 1) * factor); ++i) {
                    const float* p = image.at(i, j);
                    for (int c = 0; c < 3; ++c) sum[c] += p[c];
                    ++n;
                }
            out.set(x, y, sum[0] / float(n), sum[1] / float(n), sum[2] / float(n));
        }
    return out;
}

void blit(ImageRgb& dst, const ImageRgb& src, int x0, int y0) {
    for (int y = std::max(0, -y0); y < src.height && y + y0 < dst.height; ++y)
        for (int x = std::max(0, -x0); x < src.width && x + x0 < dst.width; ++x) {
            const float* p = src.at(x, y);
            dst.set(x + x0, y + y0, p[0], p[1], p[2]);
        }
}

}  // namespace sdf
