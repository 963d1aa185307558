/// @file mesh_spec.h
/// @brief Where a config's mesh comes from: a file found on the data search path, or a
/// procedural shape with its parameters.
///
///   "mesh": "dragon.obj"                                   a file on the search path
///   "mesh": {"file": "meshes/x.obj"}                       the same, as an object
///   "mesh": {"shape": "sphere", "subdivisions": 4}         a procedural shape
/// Search path, first match wins: the config's "data_path" entries (relative to the config
/// file), then $SDF_DATA_PATH (colon-separated), then <repo>/data/meshes and ../shared/meshes.
#pragma once

#include <string>
#include <vector>

#include "cpu_reference/mesh/triangle_mesh.h"
#include "harness/config/json_reader.h"

namespace sdf {

struct MeshSpec {
    std::string file;          ///< as written in the config (file meshes)
    std::string shape;         ///< procedural shape name (procedural meshes)
    nlohmann::json parameters; ///< procedural parameters
    std::string label() const { return shape.empty() ? file : shape; }
};

/// Parses r[key] (a string or an object).
MeshSpec parse_mesh_spec(JsonReader& r, const std::string& key);
/// Parses "shape:NAME" or a file name, as given on a command line.
MeshSpec mesh_spec_from_argument(const std::string& argument);

/// The directories searched for mesh files, in order.
std::vector<std::string> data_search_path(const std::vector<std::string>& config_entries = {},
                                          const std::string& config_dir = "");

/// Full path of a mesh file; throws listing the directories searched.
std::string locate_mesh_file(const std::string& name, const std::vector<std::string>& search_path);

/// Loads or generates the mesh.
TriangleMesh load_mesh(const MeshSpec& spec, const std::vector<std::string>& search_path);

/// Names of the procedural shapes.
std::vector<std::string> procedural_shape_names();

}  // namespace sdf
