/// @file points_file.h
/// @brief Query points as the command-line tools read them (sdf-query, sdf-eval): "x y z"
/// per line in world units, blank lines and '#' comment lines skipped; or a NumPy `.npy`
/// file of shape (N, 3) (harness/io/npy_file.h), chosen by the extension.
///
/// A line that is not exactly three finite numbers is an error naming the file and line
/// ("points.txt:4: expected three finite numbers ..."). So is an input without a point (an
/// empty file or stdin, only comments, a (0, 3) array): a query of nothing is most often the
/// wrong file or a step before that failed, and a tool that printed nothing and exited 0
/// would hide it ("points.txt: no points: expected ...").
#pragma once

#include <string>
#include <vector>

#include "kernels/core/vec3.h"

namespace sdf {

/// The points of `path` in file order, at least one; "-" reads standard input. Throws
/// std::runtime_error when the file cannot be opened, a line is malformed or there is no point.
std::vector<Vec3d> read_points_file(const std::string& path);

}  // namespace sdf
