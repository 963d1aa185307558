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

#include "core/mesh/mesh_provenance.h"
#include "core/mesh/prepared_mesh.h"
#include "core/sampling/sampler.h"
#include "harness/experiment/experiment.h"
#include "harness/config/lattice_spec.h"
#include "harness/config/mesh_spec.h"

namespace sdf {

struct StudyInputs {
    MeshSpec mesh;
    std::vector<std::string> search_path;
    std::string base_dir;  ///< the config's directory: relative mesh names are looked up there first
    double margin = 0.1;   ///< fraction of the mesh's largest extent added on every side
    std::vector<LatticeSpec> lattices;
    std::vector<std::string> lattice_labels;  ///< unique, one per lattice (lattice_spec_labels)
    SamplerOptions sampler;
};

/// Reads mesh, data_path, domain, lattices and sampler from the root config and validates
/// what a run would need: the mesh file is located, shape parameters checked, at least one
/// lattice given and their names unique, and the sampler's backend present on this machine.
StudyInputs read_study_inputs(JsonReader& config, const RunContext& context, bool lattices_required = true);

/// The host memory of a study over `in.lattices` (memory_budget.h): kBaseBytes plus
/// `bytes_per_point` times the largest lattice's points, or their sum when the study holds
/// every lattice's field at once (`all_at_once`).
MemoryNeed lattice_memory_need(const StudyInputs& in, uint64_t bytes_per_point, bool all_at_once, const std::string& step);

/// Reads "data_path" and returns the search path it makes (mesh_spec.h).
std::vector<std::string> read_search_path(JsonReader& config, const RunContext& context);
/// Reads the optional "domain" object; returns its margin.
double read_domain_margin(JsonReader& config);
/// Throws ConfigError at `key`.backend when `options` name a backend this machine lacks.
void require_backend(const SamplerOptions& options, const JsonReader& config, const std::string& key);

/// Loads (or generates) and prepares the mesh; prints its summary and warnings to `log`.
PreparedMesh load_prepared_mesh(const StudyInputs& inputs, std::ostream& log);

// The mesh's record in headers and manifests: describe_prepared_mesh (core/mesh/mesh_provenance.h).

/// "512,000"
std::string with_commas(int64_t v);

}  // namespace sdf
