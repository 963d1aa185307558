/// @file image_io.h
/// @brief Image files: PNG for viewing, EXR for exact values with the provenance in the
/// header, through OpenImageIO; PPM/PFM when the build has no OpenImageIO (SDF_HAVE_OIIO
/// off, e.g. the GPU machine). Every file is written atomically and never replaces an
/// existing one unless asked (harness/io/atomic_file.h).
///
/// Attributes: the top-level keys of a JSON object, stored as "sdf:<key>" EXR header
/// attributes (strings as strings, integers as int, other numbers as float, objects and
/// arrays as their JSON text) and as PNG text chunks. The project stores at least
/// config_hash, git_commit, git_dirty, render_seconds, reconstruction and camera.
///
/// Without OpenImageIO, ".png" is written as ".ppm" and ".exr" as ".pfm" next to a
/// "<file>.json" with the attributes; a note on stderr says so, and the functions return
/// the path actually written.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "harness/io/atomic_file.h"
#include "harness/render/image_buffer.h"

namespace sdf {

/// True when this build writes PNG and EXR (OpenImageIO found at configure time).
bool have_openimageio();

/// Writes an RGB image; the format follows the extension (.png, .exr, .ppm, .pfm; with
/// OpenImageIO also anything it writes). Returns the path written.
std::string write_image(const std::string& path, const ImageRgb& image,
                        const nlohmann::json& attributes = nlohmann::json::object(),
                        Overwrite overwrite = Overwrite::Forbid);

/// A render's exact per-pixel values in one EXR: channels R, G, B (the shade), Z (depth
/// along the ray; 0 for misses), N.X, N.Y, N.Z (normal), hit (0 miss, 1 surface, 2
/// clipped), all float32. Without OpenImageIO: <base>.pfm (shade), <base>.depth.pfm,
/// <base>.normal.pfm and <base>.json. Returns the path written (the EXR or the shade PFM).
std::string write_render_exr(const std::string& path, const RenderedImage& image,
                             const nlohmann::json& attributes = nlohmann::json::object(),
                             Overwrite overwrite = Overwrite::Forbid);

/// Reads the first three channels of an image (PPM/PFM always; other formats need
/// OpenImageIO). Throws naming the file.
ImageRgb read_image_rgb(const std::string& path);

/// A header attribute as text ("" when absent; requires OpenImageIO).
std::string read_image_attribute(const std::string& path, const std::string& name);

/// `path` with its extension replaced ("a/b.png", ".ppm" -> "a/b.ppm").
std::string replace_extension(const std::string& path, const std::string& extension);

}  // namespace sdf
