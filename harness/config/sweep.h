/// @file sweep.h
/// @brief Sweeps: a config's top-level "sweep" lists values for key paths; the runs are the
/// cartesian product, each named after its parameters.
///
///   "sweep": {
///     "sampler.precision": ["float", "double"],                  -> labels precision_float, ...
///     "lattices": {"labels": ["33k", "200k"], "values": [[...], [...]]}   -> labels 33k, 200k
///   }
/// A key path is dot-separated with [i] for array entries ("lattices[0].resolution"); it
/// must name an existing array entry, and objects on the way are created. A value's label
/// is given ("labels") or derived: scalars as written, arrays of scalars joined by 'x'
/// ([32,32,32] -> 32x32x32), prefixed with the key's last name ("resolution_32x32x32").
/// The run's name is "<name>-<label>-<label>..." (axes in key order).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace sdf {

struct SweepPoint {
    std::string name;            ///< the config's name, or "<name>-<labels>" in a sweep
    nlohmann::json parameters;   ///< {"key.path": value} for this point ({} without a sweep)
    nlohmann::json config;       ///< the config with the values set and "sweep" removed
};

/// One point per combination (a single point without "sweep"). `name` is the config's
/// "name"; errors name `file` and the sweep key.
std::vector<SweepPoint> expand_sweep(const nlohmann::json& config, const std::string& file, const std::string& name);

/// Sets `value` at a key path in `j`; throws std::invalid_argument describing what is wrong.
void set_at_key_path(nlohmann::json& j, const std::string& key_path, const nlohmann::json& value);

/// A label from a value: scalars as written, arrays of scalars joined with 'x'; "" when the
/// value has no short form. Characters other than letters, digits, '.', '_', '-' become '_'.
std::string sweep_value_label(const nlohmann::json& value);

}  // namespace sdf
