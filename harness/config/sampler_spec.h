/// @file sampler_spec.h
/// @brief The one JSON codec of SamplerOptions (core/sampling/sampler_options.h), generated
/// from its field table: the "sampler" object of a config,
///   {"backend": "auto" | "cpu" | "cuda", "method": "bvh" | "brute_force", "kernel": "...",
///    "precision": "float" | "double", "sign": "auto" | "pseudonormal" | "winding",
///    "threads": 0, "bcc_strategy": "two_grids" | "double_resolution", "progress": true,
///    "device": 0, "devices": "all" | [0, 1] | [], "max_points_per_piece": 0, "max_triangles_per_chunk": 0,
///    "points_per_thread": 0, "band_width": 0, "bvh_build": "auto" | "host" | "device",
///    "min_points_per_device": 8388608}
/// and every other place options travel as JSON: the tools' command lines, the Python
/// module's keywords, the MPI wire, the run's manifest, the field cache's key. Every absent
/// key takes the struct's default (docs/harness.md, "Defaults").
///
/// Backends, methods and kernels (the first is the default) come from the sampler table,
/// harness/sampling/sampler_table.h. "auto" is resolved here, when the options are read
/// (resolve_sampler_backend), so the manifest records the backend that ran; it takes no
/// "kernel". The codec lives in harness/, not beside the struct in core/, because its checks
/// need the sampler table and its messages JsonReader (file, key path, "did you mean"), both
/// harness code; the field table it is generated from is core's.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/sampling/sampler.h"
#include "harness/config/json_reader.h"

namespace sdf {

/// Reads and validates the sampler object (kernel names per backend included), resolves
/// "auto" (recording the resolved backend) and calls r.finish().
SamplerOptions parse_sampler_options(JsonReader& r);

/// The same for options that arrive as JSON from elsewhere (the tools' command lines, the
/// Python module, the MPI wire); errors name `source` and the key ("sampler.kernel").
SamplerOptions sampler_options_from_json(const nlohmann::json& j, const std::string& source);

/// Every field, by name (enums by their names); sampler_options_from_json reads it back to
/// the same options (with "auto" resolved).
nlohmann::json sampler_options_to_json(const SamplerOptions& o);

/// SamplerOptions::devices from its JSON: "all", a list of distinct ordinals >= 0 ([]: the
/// one "device"), or the command line's text of either ("all", "0,1", "[0, 1]"); nullopt with
/// `error` saying what is wrong.
std::optional<DeviceSelection> parse_device_selection(const nlohmann::json& value, std::string& error);

/// The fields that decide the sampled values (OptionRole::Result), for the field cache's
/// key: every field of that role, so a new one is keyed once it has its row. The BCC
/// strategy is written as "-" on CC lattices, where it changes nothing.
nlohmann::json sampler_result_identity(const SamplerOptions& o, LatticeType lattice_type);

/// The names a sampler option of the Named or Backend/Method domains accepts, for the tools'
/// option checks ("precision" -> {"float", "double"}); empty for other keys.
std::vector<std::string> sampler_option_choices(const std::string& key);

/// "cpu brute_force: vectorized, eberly; cpu bvh: brick, ..." from the sampler table, for
/// help texts and messages.
std::string sampler_kernels_help();

}  // namespace sdf
