/// @file cuda_sampler.h
/// @brief The CUDA brute-force sampler (thesis section 3.3): kernels "thesis" (faithful to
/// the chapter) and "tuned" (as fast as we can make it), both behind the Sampler interface.
#pragma once

#include <memory>

#include "core/sampling/sampler.h"

namespace sdf::cuda {

std::unique_ptr<Sampler> make_cuda_brute_force_sampler(const SamplerOptions& options);

}  // namespace sdf::cuda
