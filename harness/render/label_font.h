/// @file label_font.h
/// @brief The TrueType font the grids' labels are drawn with (OpenImageIO render_text needs
/// one). Looked up in this order: $SDF_FONT, then DejaVu Sans from Debian's
/// fonts-dejavu-core (scripts/debian-packages.txt, group "build"), then a few other common
/// locations.
#pragma once

#include <string>

namespace sdf {

/// Absolute path of the label font. Throws std::runtime_error listing every place tried and
/// how to fix it (install fonts-dejavu-core, or set SDF_FONT) when none is found.
std::string find_label_font();

}  // namespace sdf
