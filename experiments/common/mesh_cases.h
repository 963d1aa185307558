/// @file mesh_cases.h
/// @brief The "cases" of the timing experiments (speedup, peers): meshes, each with a label
/// and the sample counts to time it at; and loading a case's mesh for a run.
///
///   "cases": [{"label": "dragon", "mesh": "dragon.obj", "samples": [32768, 262144]}]
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "harness/experiment/experiment.h"
#include "harness/config/mesh_spec.h"

namespace sdf {

struct MeshCase {
    std::string label;
    MeshSpec mesh;
    std::vector<int64_t> samples;
};

/// Reads "cases": at least one, each with a label, a mesh (located on `search_path`,
/// relative names first in `base_dir`) and at least one sample count, each 8 or more.
std::vector<MeshCase> read_mesh_cases(JsonReader& config, const std::vector<std::string>& search_path,
                                      const std::string& base_dir);

/// Loads and prepares the case's mesh (summary and warnings to the run's log) and records
/// its source and hash under inputs.meshes.<label>.
PreparedMesh load_case_mesh(const MeshCase& c, const std::vector<std::string>& search_path, const std::string& base_dir,
                            RunContext& ctx);

}  // namespace sdf
