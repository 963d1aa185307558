/// @file points_file.h
/// @brief Query points as the command-line tools read them (sdf-query, sdf-eval): "x y z"
/// per line in world units, blank lines and '#' comment lines skipped; or a NumPy `.npy`
/// file of shape (N, 3) (harness/io/npy_file.h), chosen by the extension.
///
/// A line that is not exactly three finite numbers is an error naming the file and line
/// ("points.txt:4: expected three finite numbers ...").
#pragma once

#include <string>
#include <vector>

#include "kernels/core/vec3.h"

namespace sdf {

/// The points of `path` in file order; "-" reads standard input. Throws std::runtime_error
/// when the file cannot be opened or a line is malformed.
std::vector<Vec3d> read_points_file(const std::string& path);

}  // namespace sdf
