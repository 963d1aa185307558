/// @file device_buffer.h
/// @brief RAII device memory and CUDA-event timing for the launchers.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <vector>

#include "cuda/util/cuda_check.h"
#include "cuda/util/device_guard.h"

namespace sdf::cuda {

/// Device memory for DeviceBuffer: stream-ordered (cudaMallocFromPoolAsync/cudaFreeAsync on
/// stream 0) from a pool of this module's own on each device, which keeps freed memory for
/// the next allocation instead of returning it to the driver: a BVH build or a point query
/// allocates and frees a dozen buffers, and cudaMalloc + cudaFree (which waits for the whole
/// device) cost more than the kernels at a million points. The pool keeps up to 1/16 of the
/// device's memory (the rest goes back at the next synchronisation); devices without pools
/// use cudaMalloc/cudaFree.
void* allocate_device_bytes(size_t bytes, int& device);
void free_device_bytes(void* ptr, int device) noexcept;

/// The current device's memory that an allocation of ours can take: the driver's free memory
/// (cudaMemGetInfo) plus what our pool keeps unused, which cudaMemGetInfo counts as taken.
/// What slabs and pieces are sized by.
size_t free_device_memory();

template <typename T>
class DeviceBuffer {
public:
    DeviceBuffer() = default;
    explicit DeviceBuffer(size_t count) { allocate(count); }
    ~DeviceBuffer() { release(); }
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;
    DeviceBuffer(DeviceBuffer&& o) noexcept : ptr_(o.ptr_), count_(o.count_), device_(o.device_) {
        o.ptr_ = nullptr;
        o.count_ = 0;
    }

    void allocate(size_t count) {
        release();
        if (count > 0) ptr_ = static_cast<T*>(allocate_device_bytes(count * sizeof(T), device_));
        count_ = count;
    }
    void release() {
        if (ptr_) free_device_bytes(ptr_, device_);
        ptr_ = nullptr;
        count_ = 0;
    }
    /// The memory is allocated and freed in stream 0's order: a copy on another stream into
    /// a fresh allocation first waits for stream 0, and work on another stream must be done
    /// before the buffer is released. A fresh allocation is on the current device; copies
    /// into and out of an allocated buffer run on its own device (a stream of the caller's
    /// must be that device's).
    void upload(const T* host, size_t count, cudaStream_t stream = 0) {
        if (count > count_) {
            allocate(count);
            if (stream != 0) CUDA_CHECK(cudaStreamSynchronize(0));
        }
        if (count == 0) return;
        const DeviceGuard on(device_);
        CUDA_CHECK(cudaMemcpyAsync(ptr_, host, count * sizeof(T), cudaMemcpyHostToDevice, stream));
    }
    template <typename Allocator>
    void upload(const std::vector<T, Allocator>& host, cudaStream_t stream = 0) { upload(host.data(), host.size(), stream); }
    void download(T* host, size_t count, cudaStream_t stream = 0) const {
        if (count == 0) return;
        const DeviceGuard on(device_);
        CUDA_CHECK(cudaMemcpyAsync(host, ptr_, count * sizeof(T), cudaMemcpyDeviceToHost, stream));
    }
    T* get() const { return ptr_; }
    size_t size() const { return count_; }
    /// The device the memory is on (the current one when it was allocated).
    int device() const { return device_; }

private:
    T* ptr_ = nullptr;
    size_t count_ = 0;
    int device_ = 0;  ///< the device the memory is on (freed there)
};

/// Page-locked host memory (cudaMallocHost): the device copies into it at full bus speed and
/// asynchronously, which pageable memory does not allow.
class PinnedBytes {
public:
    explicit PinnedBytes(size_t bytes) : bytes_(bytes) {
        if (bytes > 0) CUDA_CHECK(cudaMallocHost(&ptr_, bytes));
    }
    ~PinnedBytes() {
        if (ptr_) cudaFreeHost(ptr_);
    }
    PinnedBytes(const PinnedBytes&) = delete;
    PinnedBytes& operator=(const PinnedBytes&) = delete;
    char* get() const { return static_cast<char*>(ptr_); }
    size_t size() const { return bytes_; }

private:
    void* ptr_ = nullptr;
    size_t bytes_ = 0;
};

/// Accumulates the time between begin() and end() pairs on one stream, in seconds. Its
/// events belong to the device it was made on (the current one, or `device`); begin() and
/// end() record them there, on that device's stream.
class EventTimer {
public:
    EventTimer() : EventTimer(current_device()) {}
    explicit EventTimer(int device) : device_(device) {
        const DeviceGuard on(device_);
        CUDA_CHECK(cudaEventCreate(&start_));
        CUDA_CHECK(cudaEventCreate(&stop_));
    }
    ~EventTimer() {
        cudaEventDestroy(start_);
        cudaEventDestroy(stop_);
    }
    EventTimer(const EventTimer&) = delete;
    EventTimer& operator=(const EventTimer&) = delete;

    void begin(cudaStream_t stream = 0) {
        const DeviceGuard on(device_);
        CUDA_CHECK(cudaEventRecord(start_, stream));
    }
    void end(cudaStream_t stream = 0) {
        const DeviceGuard on(device_);
        CUDA_CHECK(cudaEventRecord(stop_, stream));
        CUDA_CHECK(cudaEventSynchronize(stop_));
        float ms = 0;
        CUDA_CHECK(cudaEventElapsedTime(&ms, start_, stop_));
        seconds_ += 1e-3 * ms;
    }
    double seconds() const { return seconds_; }
    int device() const { return device_; }

private:
    int device_ = 0;
    cudaEvent_t start_{}, stop_{};
    double seconds_ = 0;
};

}  // namespace sdf::cuda
