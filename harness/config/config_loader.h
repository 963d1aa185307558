/// @file config_loader.h
/// @brief Reads an experiment config with its "parent" chain.
///
///   configs/dragon.json:  {"parent": "_mesh_study.json", "name": "dragon", "mesh": "dragon.obj"}
///
/// "parent" is a path relative to the config that names it. The child is merged over its
/// parent: keys the child gives override the parent's, objects merge recursively, arrays
/// (and every other value) replace the parent's as a whole, and a child value of null
/// removes the key. Parents may have parents; a cycle is an error naming the chain.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sdf {

struct LoadedConfig {
    std::string path;                 ///< as given
    std::vector<std::string> files;   ///< absolute paths: the config, its parent, grandparent...
    nlohmann::json as_written;        ///< the config file itself
    nlohmann::json merged;            ///< after inheritance, without "parent"
    /// For messages: the path, and the parents when there are any.
    std::string label() const;
};

LoadedConfig load_config(const std::string& path);

/// `child` merged over `parent` (see above).
nlohmann::json merge_config(const nlohmann::json& parent, const nlohmann::json& child);

}  // namespace sdf
