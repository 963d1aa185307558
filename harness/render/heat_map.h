/// @file heat_map.h
/// @brief Error images for the grids: the per-pixel normal angle error of a render against
/// its reference in a perceptually uniform colour map (viridis), with coverage mismatches
/// marked in a colour outside the map.
///
///   both hit:           viridis(min(angle / max_degrees, 1))  (dark blue 0 .. yellow max)
///   hit in one only:    magenta (1, 0, 1)
///   hit in neither:     white (the background)
#pragma once

#include "harness/render/image_buffer.h"

namespace sdf {

/// viridis(t) for t in [0, 1] (clamped): piecewise linear through 9 samples of the
/// matplotlib map.
void viridis(float t, float rgb[3]);

ImageRgb normal_error_heat_map(const RenderedImage& test, const RenderedImage& reference, double max_degrees);

/// A horizontal colour bar 0 .. max (width x height) for a grid legend.
ImageRgb viridis_bar(int width, int height);

/// The bar with black tick marks at `ticks` + 1 evenly spaced values (0 .. max) and a white
/// band of `text_band` pixels below for their values (GridCell::ticks draws them).
ImageRgb colour_bar_with_ticks(int width, int bar_height, int ticks, int text_band);

}  // namespace sdf
