/// @file make_sampler.h
/// @brief The one place that maps sampler options to a backend implementation.
#pragma once

#include <memory>

#include "core/sampling/sampler.h"

namespace sdf {

/// Creates the sampler the options name; throws naming the known ones otherwise.
std::unique_ptr<Sampler> make_sampler(const SamplerOptions& options);

/// True when this build has the CUDA backend and a GPU is present.
bool cuda_backend_available();

}  // namespace sdf
