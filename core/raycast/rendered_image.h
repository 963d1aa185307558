/// @file rendered_image.h
/// @brief A rendered image as every renderer returns it (ray caster on CPU or GPU, mesh
/// reference): one PixelRecord per pixel, row 0 at the top, plus a JSON description of how
/// it was made (renderer, backend, reconstruction or mesh, camera, timings).
#pragma once

#include <vector>

#include <nlohmann/json.hpp>

#include "kernels/raycast/pixel_record.h"

namespace sdf {

struct RenderedImage {
    int width = 0, height = 0;
    std::vector<PixelRecord> pixels;  ///< row-major, x fastest
    nlohmann::json info = nlohmann::json::object();

    RenderedImage() = default;
    RenderedImage(int w, int h) : width(w), height(h), pixels(size_t(w) * size_t(h)) {}

    const PixelRecord& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
    PixelRecord& at(int x, int y) { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
    int64_t hit_count() const {
        int64_t n = 0;
        for (const PixelRecord& p : pixels) n += p.is_hit() ? 1 : 0;
        return n;
    }
};

}  // namespace sdf
