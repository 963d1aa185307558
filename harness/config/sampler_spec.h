/// @file sampler_spec.h
/// @brief The "sampler" object of a config:
///   {"backend": "cpu" | "cuda", "method": "brute_force", "kernel": "...",
///    "threads": 0, "precision": "float" | "double", "bcc_strategy": "two_grids" | "double_resolution"}
#pragma once

#include "cpu_reference/sampling/sampler.h"
#include "harness/config/json_reader.h"

namespace sdf {

SamplerOptions parse_sampler_options(JsonReader& r);
nlohmann::json sampler_options_to_json(const SamplerOptions& o);

}  // namespace sdf
