/// @file cuda_check.h
/// @brief Every CUDA call is checked; a failure throws with the call, the file and line and,
/// for launches, the kernel's name. Debug builds synchronise after each launch so that a
/// fault is reported against the kernel that caused it (pbrt-v4's GPUParallelFor).
#pragma once

#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace sdf::cuda {

[[noreturn]] inline void throw_cuda_error(cudaError_t err, const char* what, const char* file, int line) {
    throw std::runtime_error(std::string("CUDA error in ") + what + " (" + file + ":" + std::to_string(line) +
                             "): " + cudaGetErrorName(err) + ": " + cudaGetErrorString(err));
}

}  // namespace sdf::cuda

#define CUDA_CHECK(call)                                                                   \
    do {                                                                                   \
        cudaError_t sdf_err_ = (call);                                                     \
        if (sdf_err_ != cudaSuccess) ::sdf::cuda::throw_cuda_error(sdf_err_, #call, __FILE__, __LINE__); \
    } while (0)

/// Checks the launch of `kernel_name` (a string literal); synchronises in debug builds.
#ifndef NDEBUG
#define CUDA_CHECK_LAUNCH(kernel_name)                                                           \
    do {                                                                                         \
        cudaError_t sdf_err_ = cudaGetLastError();                                               \
        if (sdf_err_ == cudaSuccess) sdf_err_ = cudaDeviceSynchronize();                          \
        if (sdf_err_ != cudaSuccess) ::sdf::cuda::throw_cuda_error(sdf_err_, "kernel " kernel_name, __FILE__, __LINE__); \
    } while (0)
#else
#define CUDA_CHECK_LAUNCH(kernel_name)                                                           \
    do {                                                                                         \
        cudaError_t sdf_err_ = cudaGetLastError();                                               \
        if (sdf_err_ != cudaSuccess) ::sdf::cuda::throw_cuda_error(sdf_err_, "kernel " kernel_name, __FILE__, __LINE__); \
    } while (0)
#endif
