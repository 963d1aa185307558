/// @file device_guard.h
/// @brief Makes one CUDA device current for a scope and gives the caller's back at its end.
///
/// Every stream, event, buffer and launch belongs to the device current when it is made or
/// issued, and the current device is per host thread. So each CUDA object records its device
/// and each entry point of a sampler (binding, sampling, queries) makes its device current
/// with a guard: a rank, a thread or a Python call that uses device k touches device k only,
/// whatever another thread or an earlier call left current (issue 36: an event made on
/// device 0 and recorded on device 1 is cudaErrorInvalidResourceHandle).
#pragma once

#include <cuda_runtime.h>

#include "cuda/util/cuda_check.h"

namespace sdf::cuda {

class DeviceGuard {
public:
    explicit DeviceGuard(int device) : device_(device) {
        CUDA_CHECK(cudaGetDevice(&previous_));
        if (previous_ != device_) CUDA_CHECK(cudaSetDevice(device_));
    }
    ~DeviceGuard() {
        if (previous_ != device_) cudaSetDevice(previous_);
    }
    DeviceGuard(const DeviceGuard&) = delete;
    DeviceGuard& operator=(const DeviceGuard&) = delete;

private:
    int device_ = 0;
    int previous_ = 0;
};

/// The device current on this thread.
inline int current_device() {
    int device = 0;
    CUDA_CHECK(cudaGetDevice(&device));
    return device;
}

}  // namespace sdf::cuda
