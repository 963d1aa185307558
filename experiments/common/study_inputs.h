/// @file study_inputs.h
/// @brief The config keys every mesh study shares: mesh, data path, domain, lattices,
/// sampler; and loading the mesh with its warnings.
///
///   "mesh": ..., "data_path": [...], "domain": {"margin": 0.1},
///   "lattices": [ {...}, ... ], "sampler": {...}
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "cpu_reference/mesh/prepared_mesh.h"
#include "cpu_reference/sampling/sampler.h"
#include "experiments/experiment.h"
#include "harness/config/lattice_spec.h"
#include "harness/config/mesh_spec.h"

namespace sdf {

struct StudyInputs {
    MeshSpec mesh;
    std::vector<std::string> search_path;
    double margin = 0.1;  ///< fraction of the mesh's largest extent added on every side
    std::vector<LatticeSpec> lattices;
    SamplerOptions sampler;
};

/// Reads mesh, data_path, domain, lattices and sampler from the root config.
StudyInputs read_study_inputs(JsonReader& config, const RunContext& context, bool lattices_required = true);

/// Loads (or generates) and prepares the mesh; prints its summary and warnings to `log`.
PreparedMesh load_prepared_mesh(const StudyInputs& inputs, std::ostream& log);

/// Name, source, hash, counts and preparation report, for headers and manifests.
nlohmann::json describe_mesh(const PreparedMesh& mesh);

}  // namespace sdf
