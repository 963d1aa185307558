/// @file version.h
/// @brief The project's version and the git commit this build was made from, for every
/// tool's `--version` and the Python module's `__version__` (the header behind it is written
/// at build time by cmake/WriteVersionHeader.cmake; -DSDF_SOURCE_COMMIT=... names the commit of a
/// tree without .git).
#pragma once

#include <string>

namespace sdf {

/// "0.1.0" (CMakeLists.txt's project version).
std::string project_version();
/// The full commit hash, "unknown" when neither git nor SDF_SOURCE_COMMIT could tell.
std::string build_commit();
/// True when the tree had uncommitted changes to tracked files at build time (or is unknown).
bool build_dirty();
/// "sdf-query 0.1.0 (commit 5671e2c..., with uncommitted changes)", as `--version` prints it.
std::string version_line(const std::string& tool);

}  // namespace sdf
