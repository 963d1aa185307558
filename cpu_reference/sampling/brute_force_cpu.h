/// @file brute_force_cpu.h
/// @brief The CPU reference sampler (thesis section 3.1): for every point, the minimum over
/// all triangles. Multithreaded; with 1 thread it is the thesis's single-core reference.
///
/// Kernels: "vectorized" (default) finds the nearest triangle with the branch-free
/// squared_distance() over triangles stored as arrays, then re-evaluates the winner with
/// Eberly's algorithm; "eberly" runs Eberly's algorithm on every pair, as the thesis did.
#pragma once

#include <memory>

#include "core/sampling/kernel_table.h"
#include "core/sampling/sampler.h"

namespace sdf {

enum class CpuBruteForceKernel { Vectorized, Eberly };

/// The kernels of method "brute_force" on the CPU; the first is the default.
inline constexpr NamedKernel<CpuBruteForceKernel> kCpuBruteForceKernels[] = {
    {"vectorized", CpuBruteForceKernel::Vectorized},
    {"eberly", CpuBruteForceKernel::Eberly},
};

std::unique_ptr<Sampler> make_cpu_brute_force_sampler(const SamplerOptions& options);

}  // namespace sdf
