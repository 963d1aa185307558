/// @file netpbm.h
/// @brief The image formats this project can always write, OpenImageIO or not: binary PPM
/// (P6, 8 bits per channel, for viewing) and PFM (float, for exact values; "PF" for RGB,
/// "Pf" for one channel; little-endian, rows stored bottom to top as the format requires).
#pragma once

#include <string>
#include <vector>

#include "harness/io/atomic_file.h"
#include "harness/render/image_buffer.h"

namespace sdf {

/// The bytes of a PPM (8-bit, v -> round(255 clamp(v, 0, 1))) or PFM file of `image`.
std::vector<unsigned char> encode_ppm(const ImageRgb& image);
std::vector<unsigned char> encode_pfm(const ImageRgb& image);
/// One-channel PFM ("Pf") of width x height values, row 0 at the top.
std::vector<unsigned char> encode_pfm_grey(const std::vector<float>& values, int width, int height);

/// Reads a P6 PPM (maxval 255) or an RGB/grey PFM (grey is copied to all three channels).
/// Throws naming the file and what was wrong.
ImageRgb read_netpbm(const std::string& path);

}  // namespace sdf
