#include "harness/io/field_output.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

namespace sdf {

const std::vector<FieldOutputFormat>& field_output_formats() {
    // The one place where output formats plug in: ".vdb" (OpenVDB level set and Vec3f
    // gradient), ".vti" (VTK ImageData) and ".npy" (NumPy) are rows to add here, with BCC
    // fields written as their two CC sub-grids.
    static const std::vector<FieldOutputFormat> formats = {
        {".json", "the project's field file (JSON header and raw channels, docs/field-format.md)", write_field},
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
