/// @file bvh_sampler.h
/// @brief The CUDA BVH sampler (method "bvh"): the BVH is built on the CPU
/// (cpu_reference/bvh), uploaded once per mesh, searched on the GPU in float or double
/// (cuda/bvh/bvh_kernel.cuh, cuda/bvh/bvh_warp_kernel.cuh, cuda/bvh/bvh_candidates_kernel.cuh: "warp" by
/// default, "candidates" (a brick's shared candidate list; the one that skips the bricks
/// outside a narrow band), "brick", "seeded", "unseeded"); point lists are sorted into Morton
/// order on the device and searched 128 at a time by the warp kernels, and the winner
/// of every point evaluated in double by the same finalize_samples() as the brute-force
/// sampler, so fields equal the CPU samplers' to double rounding except at ties.
#pragma once

#include <memory>

#include "core/sampling/kernel_table.h"
#include "core/sampling/sampler.h"

namespace sdf::cuda {

/// The BVH search kernels on the GPU (the values index the launch switch of bvh_sampler.cu).
enum class BvhGpuKernel : int { Brick = 0, Seeded = 1, Unseeded = 2, Warp = 3, Candidates = 4 };

/// The kernels of method "bvh" on the GPU; the first is the default.
inline constexpr NamedKernel<BvhGpuKernel> kCudaBvhKernels[] = {
    {"warp", BvhGpuKernel::Warp},
    {"candidates", BvhGpuKernel::Candidates},
    {"brick", BvhGpuKernel::Brick},
    {"seeded", BvhGpuKernel::Seeded},
    {"unseeded", BvhGpuKernel::Unseeded},
};

std::unique_ptr<Sampler> make_cuda_bvh_sampler(const SamplerOptions& options);

}  // namespace sdf::cuda
