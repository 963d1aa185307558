/// @file bvh_sampler.h
/// @brief The CUDA BVH sampler (method "bvh"): the BVH is built on the CPU
/// (cpu_reference/bvh), uploaded once per mesh, searched on the GPU in float or double
/// (kernels/cuda/bvh_kernel.cuh: "brick" by default, "seeded", "unseeded"), and the winner
/// of every point evaluated in double by the same finalize_samples() as the brute-force
/// sampler, so fields equal the CPU samplers' to double rounding except at ties.
#pragma once

#include <memory>

#include "core/sampling/sampler.h"

namespace sdf::cuda {

std::unique_ptr<Sampler> make_cuda_bvh_sampler(const SamplerOptions& options);

}  // namespace sdf::cuda
