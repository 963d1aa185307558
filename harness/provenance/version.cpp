#include "harness/provenance/version.h"

#include "harness/build_version.h"

namespace sdf {

std::string project_version() { return SDF_VERSION; }
std::string build_commit() { return SDF_BUILD_COMMIT; }
bool build_dirty() { return SDF_BUILD_DIRTY != 0; }

std::string version_line(const std::string& tool) {
    return tool + " " + project_version() + " (commit " + build_commit() +
           (build_dirty() ? ", with uncommitted changes" : "") + ")";
}

}  // namespace sdf
