/// @file field_file.h
/// @brief The project's field file: a JSON header plus one raw little-endian array per
/// channel. Any scalar volume on a CC or BCC lattice can be stored this way, not only
/// distance fields (docs/field-format.md has the full description).
///
/// Header `NAME.json`:
///   { "format": "sdf-lattice-field", "version": 1,
///     "lattice": { "type": "cc" | "bcc", "origin": [x,y,z], "spacing": h,
///                  "resolution": [nx,ny,nz] (BCC: thesis notation [Rx,Ry,2Rz]) },
///     "channels": { "value": {"file": "NAME.value.raw", "dtype": "float32", "components": 1},
///                   "gradient": {...components 3...}, ... },
///     "value_channel": "value", "gradient_channel": "gradient" (optional), ...provenance }
/// Points are stored x fastest, then y, then z; BCC stores the primary grid, then the
/// secondary one (see kernels/lattice/lattice.h).
#pragma once

#include <string>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "core/sampling/sampled_field.h"
#include "harness/io/atomic_file.h"

namespace sdf {

enum class FieldDtype { Float32, Float64 };

struct FieldWriteOptions {
    FieldDtype dtype = FieldDtype::Float32;
    Overwrite overwrite = Overwrite::Forbid;
    bool closest_triangle = true;  ///< write the closest-triangle channel when present
};

/// Writes NAME.json and its channel files next to it (NAME = header path without ".json").
/// Channel files are written first and the header last, each atomically; an existing field is
/// replaced (Overwrite::Allow) in one atomic step, the header's rename (field_replacement.h), so
/// NAME.json describes the old field whole or the new one whole at every instant. Values the
/// stored type cannot hold (a finite value beyond float32's range) are refused, naming the channel.
void write_field(const std::string& header_path, const SampledField& field, const FieldWriteOptions& options = {});

/// One channel file of a field as write_field lays it out, for writers that fill the files
/// by parts (harness/distributed: every rank writes its slabs with MPI-IO at their offsets).
struct FieldChannelFile {
    std::string name;   ///< "distance", "gradient" or "closest_triangle"
    std::string path;   ///< NAME.<name>.raw beside the header
    FieldDtype dtype = FieldDtype::Float32;  ///< of distance and gradient; closest_triangle is int32
    int components = 1;
    size_t bytes_per_point() const;
};

/// The channel files write_field writes for `field` with `options`, in its order.
std::vector<FieldChannelFile> field_channel_files(const std::string& header_path, const SampledField& field,
                                                  const FieldWriteOptions& options);

/// The stored bytes of points [first, first + count) of `channel`, taken from `field`'s
/// arrays at the same indices: the bytes write_field puts at offset first * bytes_per_point.
std::vector<char> field_channel_bytes(const SampledField& field, const FieldChannelFile& channel, size_t first,
                                      size_t count);

/// Writes the header of `field` (atomically), whose channel files are complete: the last
/// step of write_field, and of writers that fill the channel files by parts.
void write_field_header(const std::string& header_path, const SampledField& field,
                        const std::vector<FieldChannelFile>& channels, Overwrite overwrite);

/// Refuses (std::invalid_argument naming `what`) a narrow band width w > 0 that `dtype`
/// cannot hold: below its smallest positive normal value (float32: 1.17549e-38; the band's
/// +-w would be stored as 0 or lose its digits) or beyond its largest (float32: 3.40282e38).
void require_representable_band(double w, FieldDtype dtype, const std::string& what);

/// The checks of write_field before anything is written: a narrow band (the field's
/// sampler.band.width) that options.dtype cannot hold is refused, naming `header_path`.
void require_storable(const SampledField& field, const FieldWriteOptions& options, const std::string& header_path);

/// Reads a field written by write_field or by a user. The value channel becomes
/// `distance`; the gradient channel, if any, `gradient`. Errors name the file and key.
SampledField read_field(const std::string& header_path);

/// NRRD (detached-free, raw encoding) of a CC field: the value volume, and the gradient as
/// a 4-D "vector domain domain domain" volume when `with_gradient`.
void export_nrrd(const std::string& path, const SampledField& field, bool with_gradient,
                 Overwrite overwrite = Overwrite::Forbid);

/// The thesis's 8-bit export (section 3.3): 127 on the surface, lower outside, higher
/// inside; byte = clamp(round(127 - d * 127 / max|d|), 0, 255). Returns the scale used.
double export_uint8(const std::string& path, const SampledField& field, Overwrite overwrite = Overwrite::Forbid);

/// JSON description of a lattice as stored in headers and manifests.
nlohmann::json lattice_to_json(const Lattice& lattice);
/// Reads a lattice, its size checked against `storage`'s largest (a sparse band's file may be larger).
Lattice lattice_from_json(const nlohmann::json& j, const std::string& file, LatticeStorage storage = LatticeStorage::Dense);

}  // namespace sdf
