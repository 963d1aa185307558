/// @file host_device.h
/// @brief The one macro that lets a function run on the CPU and on the GPU.
///
/// Every kernel in kernels/ is written once and marked SDF_CPU_GPU, as pbrt-v4 does with
/// PBRT_CPU_GPU: under nvcc it expands to `__host__ __device__`, elsewhere to nothing. Code
/// marked this way uses no virtual functions, exceptions or std containers.
#pragma once

#if defined(__CUDACC__)
#define SDF_CPU_GPU __host__ __device__
#define SDF_INLINE __forceinline__
#else
#define SDF_CPU_GPU
#define SDF_INLINE inline __attribute__((always_inline))
#endif

#if defined(__CUDA_ARCH__)
#define SDF_IS_GPU_CODE 1
#else
#define SDF_IS_GPU_CODE 0
#endif

// Device-side checks in the manner of assert(): compiled out of release builds.
#if !defined(NDEBUG)
#include <cassert>
#define SDF_DCHECK(cond) assert(cond)
#else
#define SDF_DCHECK(cond) ((void)0)
#endif
