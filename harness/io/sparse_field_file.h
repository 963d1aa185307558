/// @file sparse_field_file.h
/// @brief The field file's sparse variant (docs/field-format.md, "The sparse band's field
/// file"): a sparse narrow band (core/sampling/sparse_band.h) stored as its blocks, never
/// densified, so that the file grows with the band, not with the lattice.
///
/// The header NAME.json is a field header with "layout": "sparse_band" and a "band" object
/// (width, blocks, active_blocks, mixed_blocks); its channels, beside it, are the band's
/// arrays as held in memory:
///   active_blocks     int64, one id per active block, ascending
///   distance          float32 | float64, 512 per active block (block-local order, x fastest)
///   gradient          the same, 3 components (optional)
///   closest_triangle  int32, 512 per active block (kOutsideBandTriangle off the band), or,
///                     for a band without the closest triangle channel, instead:
///   band_points       uint64, 8 words (512 bits) per active block (set: |d| <= W)
///   tile_signs        uint64, one bit per block of the lattice (set: an inside tile, -W)
///   mixed_blocks      int64, one id per mixed block, ascending
///   mixed_signs       uint64, 8 words (512 bits) per mixed block (set: inside, -W)
/// Written as the dense file is (field_replacement.h): channel files first under fresh
/// names, the header last, atomically. read_sparse_field() checks every count against the
/// lattice and every channel's size against its file before it allocates; densifying what
/// it reads gives the dense `--band W` field (read_field of that file) value for value.
#pragma once

#include <string>

#include "core/sampling/sparse_band.h"
#include "harness/io/field_file.h"

namespace sdf {

/// The header's "layout" of a sparse band's file.
inline constexpr const char* kSparseBandLayout = "sparse_band";

struct SparseFieldWriteOptions {
    FieldDtype dtype = FieldDtype::Float32;  ///< of distance and gradient
    bool gradient = true;                    ///< write the gradient channel: refused of a band without it (BandChannels)
    Overwrite overwrite = Overwrite::Forbid;
};

/// Writes `band` as NAME.json and its channel files (NAME = header path without ".json"): the
/// closest triangles where the band holds them, else its band_points mask.
/// A band width or a value the dtype cannot hold is refused, naming the file, and so is
/// options.gradient of a band without the gradient channel (std::invalid_argument).
void write_sparse_field(const std::string& header_path, const SparseBandField& band,
                        const SparseFieldWriteOptions& options = {});

/// Reads a file written by write_sparse_field. Values stored as float32 come back as the
/// doubles they round to, and so does W (the header's exact width, rounded as the file's
/// own +-W values are): densified, it is read_field() of the dense float32 file. Errors (std::runtime_error, std::invalid_argument) name the file,
/// the key or channel, and what was expected.
SparseBandField read_sparse_field(const std::string& header_path);
/// The same from the header's JSON, already read from `header_path` (read_json_file): a tool
/// that looks at the header first (is_sparse_field_header, "gradient_channel") parses it once.
SparseBandField read_sparse_field(const std::string& header_path, const nlohmann::json& header);

/// Whether the field header at `header_path` is a sparse band's ("layout": "sparse_band").
/// Throws, naming the file, when it is not readable JSON (read_field's first check).
bool is_sparse_field_file(const std::string& header_path);
/// The same for a header already parsed.
bool is_sparse_field_header(const nlohmann::json& header);

/// read_field() of a dense field file; of a sparse band's, its densified field (every
/// lattice point: the dense `--band W` field), refused past the host memory check
/// (require_host_memory, naming the size and `where`). The tools that reconstruct (sdf-eval,
/// sdf-render) read every field file this way.
SampledField read_field_densified(const std::string& header_path, const std::string& where);

/// `band` densified (the dense `--band W` field), refused past the host memory check
/// (naming `what`, its size and `where`); without `gradient` the field has none (a file read
/// without its gradient channel).
SampledField densify_within_memory(const SparseBandField& band, bool gradient, const std::string& what,
                                   const std::string& where);

}  // namespace sdf
