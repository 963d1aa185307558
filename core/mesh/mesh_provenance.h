/// @file mesh_provenance.h
/// @brief Which mesh a field was sampled from, as a type: SampledField::mesh. Every front end
/// (run-experiment's studies, sdf-sample, the Python module) describes a prepared mesh with
/// the one describe_prepared_mesh(), so field headers and manifests carry the same record.
///
/// JSON (harness/schema/run_schema.json, "mesh"): {"name", "source", "sha256", "vertices",
/// "triangles" (prepared counts), "bounds": {"min", "max"}, "report": {what preparation
/// found: mesh_report_to_json}}. An empty record (a field made from arrays) is {}.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "core/bounds3.h"

namespace sdf {

class PreparedMesh;
struct MeshReport;

struct MeshProvenance {
    std::string name, source, sha256;
    int64_t vertices = 0, triangles = 0;  ///< after preparation
    bool has_bounds = false;              ///< records written before bounds had none
    Bounds3 bounds;
    nlohmann::json report = nlohmann::json::object();  ///< mesh_report_to_json(), as recorded

    bool empty() const { return name.empty() && sha256.empty(); }
};

MeshProvenance describe_prepared_mesh(const PreparedMesh& mesh);

/// What mesh preparation found (core/mesh/prepared_mesh.h: MeshReport), for the record.
nlohmann::json mesh_report_to_json(const MeshReport& report);

void to_json(nlohmann::json& j, const MeshProvenance& m);
/// Reads what to_json wrote, and the shorter record sdf-sample and the Python module wrote
/// before (no bounds; "components" and "sign_reliable" beside the counts, read into the
/// report); a known key of the wrong type throws std::runtime_error naming it.
void from_json(const nlohmann::json& j, MeshProvenance& m);

}  // namespace sdf
