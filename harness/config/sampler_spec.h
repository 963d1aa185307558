/// @file sampler_spec.h
/// @brief The "sampler" object of a config:
///   {"backend": "cpu" | "cuda" | "auto", "method": "brute_force" | "bvh", "kernel": "...",
///    "threads": 0, "precision": "float" | "double", "sign": "auto" | "pseudonormal" | "winding",
///    "bcc_strategy": "two_grids" | "double_resolution",
///    "progress": true, "device": 0, "max_points_per_piece": 0, "max_triangles_per_chunk": 0,
///    "points_per_thread": 0}
/// Backends, methods and kernels (the first is the default) come from the sampler table,
/// harness/sampling/sampler_table.h. "auto" is cuda when this build has the CUDA backend and a GPU is present, else
/// cpu (it takes no "kernel"); the choice is made when the config is read.
#pragma once

#include <string>
#include <vector>

#include "core/sampling/sampler.h"
#include "harness/config/json_reader.h"

namespace sdf {

/// Reads and validates the sampler object (kernel names per backend included) and calls
/// r.finish(). "auto" is resolved here.
SamplerOptions parse_sampler_options(JsonReader& r);
nlohmann::json sampler_options_to_json(const SamplerOptions& o);

/// "cpu brute_force: vectorized, eberly; cpu bvh: brick, ..." from the sampler table, for
/// help texts and messages.
std::string sampler_kernels_help();

}  // namespace sdf
