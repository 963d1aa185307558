#include "harness/io/field_output.h"

#include "harness/io/volume_formats.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

namespace sdf {

namespace {

static_assert(kVolumeFormats[0].format == VolumeFormat::Vdb && kVolumeFormats[1].format == VolumeFormat::Vti &&
                  kVolumeFormats[2].format == VolumeFormat::Npy && kVolumeFormats[3].format == VolumeFormat::Npz,
              "the rows below name kVolumeFormats by position");

/// A volume format of volume_formats.h as a field output row (BCC: two CC sub-grids; the
/// OpenVDB narrow band at its default width).
template <VolumeFormat F>
void write_volume(const std::string& path, const SampledField& field, const FieldWriteOptions& options) {
    VolumeWriteOptions v;
    v.dtype = options.dtype;
    v.overwrite = options.overwrite;
    write_field_as(field, path, F, v);
}

}  // namespace

const std::vector<FieldOutputFormat>& field_output_formats() {
    // The one place where output formats plug in, by extension; the volume formats' names and
    // descriptions are those of kVolumeFormats.
    static const std::vector<FieldOutputFormat> formats = {
        {".json", "the project's field file (JSON header and raw channels, docs/field-format.md)", write_field},
        {".vdb", kVolumeFormats[0].describes, write_volume<VolumeFormat::Vdb>},
        {".vti", kVolumeFormats[1].describes, write_volume<VolumeFormat::Vti>},
        {".npy", kVolumeFormats[2].describes, write_volume<VolumeFormat::Npy>},
        {".npz", kVolumeFormats[3].describes, write_volume<VolumeFormat::Npz>},
    };
    return formats;
}

void write_field_file(const std::string& path, const SampledField& field, const FieldWriteOptions& options) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    std::string known;
    for (const FieldOutputFormat& f : field_output_formats()) {
        if (ext == f.extension) return f.write(path, field, options);
        known += (known.empty() ? "" : ", ") + std::string(f.extension) + " (" + f.description + ")";
    }
    throw std::invalid_argument(path + ": unknown field file extension '" + ext + "'; expected one of " + known);
}

}  // namespace sdf
