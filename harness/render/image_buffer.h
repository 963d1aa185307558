/// @file image_buffer.h
/// @brief An RGB float image for files and grids (interleaved, row 0 at the top), and the
/// conversions from rendered images: the shaded values as grey, box downsampling.
///
/// Pixel values are display values in [0, 1] (the shading of kernels/raycast/shading.h never
/// exceeds 0.98; heat maps are in [0, 1] by construction): no transfer function is applied
/// when they are written as 8-bit PNG (v -> round(255 v)) or kept as float in EXR.
#pragma once

#include <vector>

#include "core/raycast/rendered_image.h"

namespace sdf {

struct ImageRgb {
    int width = 0, height = 0;
    std::vector<float> data;  ///< 3 floats per pixel, x fastest

    ImageRgb() = default;
    ImageRgb(int w, int h, float grey = 0.0f) : width(w), height(h), data(size_t(w) * size_t(h) * 3, grey) {}
    float* at(int x, int y) { return &data[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
    const float* at(int x, int y) const { return &data[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
    void set(int x, int y, float r, float g, float b) {
        float* p = at(x, y);
        p[0] = r; p[1] = g; p[2] = b;
    }
};

/// The shaded values of a render as grey (misses have the background value).
ImageRgb shaded_image(const RenderedImage& image);

/// Averages factor x factor blocks (the last partial row/column averages what it has).
ImageRgb downsample(const ImageRgb& image, int factor);

/// Copies `src` into `dst` with its top-left corner at (x, y), clipped to dst.
void blit(ImageRgb& dst, const ImageRgb& src, int x, int y);

}  // namespace sdf
