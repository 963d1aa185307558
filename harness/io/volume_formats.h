/// @file volume_formats.h
/// @brief A sampled field in the volume formats users open elsewhere: OpenVDB (.vdb: Houdini,
/// Blender, pyopenvdb), VTK ImageData (.vti: ParaView), NumPy (.npy, .npz). The project's own
/// field file (field_file.h) stays the lossless record; these are exports.
///
/// Every format stores CC grids, so a BCC field is written as its two CC sub-grids: the
/// primary grid at the lattice origin and the secondary grid at origin + h/2 on every axis,
/// both with spacing h (kernels/lattice/lattice.h). docs/field-format.md ("Volume formats")
/// lists the file and array names of each format.
#pragma once

#include <string>
#include <vector>

#include "core/sampling/sampled_field.h"
#include "harness/io/atomic_file.h"
#include "harness/io/field_file.h"

namespace sdf {

enum class VolumeFormat { Vdb, Vti, Npy, Npz };

struct VolumeFormatInfo {
    VolumeFormat format;
    const char* name;       ///< the config's and the tools' name, also the file extension
    const char* describes;  ///< one line for help texts and docs
};

/// The one table of volume format names: configs ("output": {"formats": [...]}), the Python
/// module and every message read it.
inline constexpr VolumeFormatInfo kVolumeFormats[] = {
    {VolumeFormat::Vdb, "vdb", "OpenVDB: distance as a FloatGrid level set (narrow band), gradient as a Vec3fGrid"},
    {VolumeFormat::Vti, "vti", "VTK ImageData XML: distance and gradient as point data"},
    {VolumeFormat::Npy, "npy", "NumPy arrays: distance [nz,ny,nx] and gradient [nz,ny,nx,3], one file each"},
    {VolumeFormat::Npz, "npz", "NumPy archive: distance, gradient, origin, spacing and lattice in one file"},
};

const char* volume_format_name(VolumeFormat format);
/// The format called `name`; throws std::invalid_argument listing the known names.
VolumeFormat volume_format_from_name(const std::string& name);
/// "vdb, vti, npy, npz": for messages.
std::string volume_format_names();

/// Whether this build can write `format`: .vdb needs OpenVDB (libopenvdb-dev) at build time.
bool volume_format_available(VolumeFormat format);

struct VolumeWriteOptions {
    /// Float32 or Float64 arrays (vti, npy, npz); OpenVDB grids are always float.
    FieldDtype dtype = FieldDtype::Float32;
    Overwrite overwrite = Overwrite::Forbid;
    /// OpenVDB narrow band: voxels with |distance| < vdb_band * h are active; the
    /// background (the value of every other voxel, signed by the side) is vdb_band * h.
    double vdb_band = 3.0;
};

/// Writes `field` at `path` in `format` and returns the files written. `path` names the file
/// of a CC field; where a format needs several files (npy's gradient, a BCC field's
/// sub-grids in vti and npy) their names are derived from it (docs/field-format.md). Every
/// target is checked before anything is written, each file is written atomically, and
/// existing files are refused unless options.overwrite allows them.
std::vector<std::string> write_field_as(const SampledField& field, const std::string& path, VolumeFormat format,
                                        const VolumeWriteOptions& options = {});

/// The files write_field_as(field, path, format) writes, without writing them.
std::vector<std::string> volume_files(const SampledField& field, const std::string& path, VolumeFormat format);

}  // namespace sdf
