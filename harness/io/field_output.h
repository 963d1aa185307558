/// @file field_output.h
/// @brief Writing a sampled field in the format its file name asks for: the one table of
/// field output formats, by extension, that the Python module's `Field.write(path)` reads
/// (and tools may): the project's own field file (".json": header plus raw channels,
/// harness/io/field_file.h) and the volume formats of harness/io/volume_formats.h (".vdb",
/// ".vti", ".npy", ".npz"; BCC fields as their two CC sub-grids).
#pragma once

#include <string>
#include <vector>

#include "harness/io/field_file.h"

namespace sdf {

struct FieldOutputFormat {
    const char* extension;    ///< with the dot, lower case: ".json"
    const char* description;  ///< for help texts and messages
    void (*write)(const std::string& path, const SampledField& field, const FieldWriteOptions& options);
};

/// The formats, in table order.
const std::vector<FieldOutputFormat>& field_output_formats();

/// Writes `field` to `path` in the format of its extension (any case); throws
/// std::invalid_argument naming the path and the supported extensions otherwise.
void write_field_file(const std::string& path, const SampledField& field, const FieldWriteOptions& options = {});

}  // namespace sdf
