/// @file cuda_sampler.h
/// @brief The CUDA brute-force sampler (thesis section 3.3): kernels "thesis" (faithful to
/// the chapter) and "tuned" (as fast as we can make it), both behind the Sampler interface.
#pragma once

#include <memory>

#include "core/sampling/kernel_table.h"
#include "core/sampling/sampler.h"

namespace sdf::cuda {

enum class CudaBruteForceKernel { Tuned, Thesis };

/// The kernels of method "brute_force" on the GPU; the first is the default.
inline constexpr NamedKernel<CudaBruteForceKernel> kCudaBruteForceKernels[] = {
    {"tuned", CudaBruteForceKernel::Tuned},
    {"thesis", CudaBruteForceKernel::Thesis},
};

std::unique_ptr<Sampler> make_cuda_brute_force_sampler(const SamplerOptions& options);

}  // namespace sdf::cuda
