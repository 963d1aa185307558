/// @file mesh_spec.h
/// @brief Where a config's mesh comes from: a file found on the data search path, or a
/// procedural shape with its parameters.
///
///   "mesh": "dragon.obj"                                   a file (see "Finding files")
///   "mesh": {"file": "meshes/x.obj"}                       the same, as an object
///   "mesh": "shape:torus"                                  a procedural shape, default parameters
///   "mesh": {"shape": "sphere", "subdivisions": 4}         a procedural shape with parameters
///
/// Finding files: an absolute name is used as it is. A relative name is looked up first in
/// the base directory (a config's own directory; for sdf-query, which has no config, the
/// current directory), then in every directory of the search path in order: the config's
/// "data_path" entries (relative to the config file), $SDF_DATA_PATH (colon-separated), then
/// <repo>/data/meshes and ../shared/meshes. The first regular file found wins; its absolute
/// path is the mesh's recorded source. When nothing is found the error lists every place tried.
///
/// Shape parameters are read and range-checked when the spec is parsed, so a dry run sees
/// their errors; the mesh itself is built by load_mesh().
#pragma once

#include <string>
#include <vector>

#include "core/mesh/triangle_mesh.h"
#include "harness/config/json_reader.h"

namespace sdf {

struct MeshSpec {
    std::string file;          ///< as written in the config (file meshes)
    std::string shape;         ///< procedural shape name (procedural meshes)
    nlohmann::json parameters = nlohmann::json::object();  ///< procedural parameters
    std::string config_file = "command line";  ///< where the spec was written, for messages
    std::string key_path = "mesh";             ///< its key there
    std::string resolved_file; ///< absolute path once located (resolve_mesh_file)
    std::string label() const { return shape.empty() ? file : shape; }
};

/// A mesh file that is on no directory of the search path. Its own type so that
/// run-experiment can exit with its own code (README, "Exit codes") and scripts/run-main can
/// fall back to the procedural study when the real meshes were never fetched.
class MeshFileNotFound : public ConfigError {
public:
    using ConfigError::ConfigError;
};

/// Parses r[key] (a string or an object); checks shape names and parameters.
MeshSpec parse_mesh_spec(JsonReader& r, const std::string& key);
/// Parses "shape:NAME" or a file name, as given on a command line; checks shape names.
MeshSpec mesh_spec_from_argument(const std::string& argument);

/// The directories searched for mesh files after the base directory, in order.
std::vector<std::string> data_search_path(const std::vector<std::string>& config_entries = {},
                                          const std::string& config_dir = "");

/// Absolute path of a mesh file: `name` itself when absolute, else the first regular file
/// among base_dir/name (when base_dir is not empty) and dir/name for every dir of
/// `search_path`. Throws listing every place tried.
std::string locate_mesh_file(const std::string& name, const std::vector<std::string>& search_path,
                             const std::string& base_dir = "");

/// For file meshes, locates the file and stores its absolute path in spec.resolved_file
/// (errors name the config file and key). Procedural specs are left as they are.
void resolve_mesh_file(MeshSpec& spec, const std::vector<std::string>& search_path, const std::string& base_dir);

/// Loads or generates the mesh (locating the file first unless already resolved).
TriangleMesh load_mesh(const MeshSpec& spec, const std::vector<std::string>& search_path,
                       const std::string& base_dir = "");

/// Names of the procedural shapes.
std::vector<std::string> procedural_shape_names();

}  // namespace sdf
