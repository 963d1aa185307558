/// @file staged_copy.h
/// @brief Copies between the caller's pageable host memory (a NumPy array, a std::vector)
/// and the device through two page-locked buffers: while the bus moves one chunk
/// asynchronously, host threads copy the other into or out of the caller's memory, so a
/// transfer runs near the bus's speed instead of the driver's single-threaded pageable path.
#pragma once

#include <cuda_runtime.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <memory>

#include "core/parallel/parallel_for.h"
#include "cuda/util/cuda_check.h"
#include "cuda/util/device_buffer.h"

namespace sdf::cuda {

class StagedCopy {
public:
    static constexpr size_t kChunkBytes = size_t(32) << 20;

    StagedCopy() = default;
    ~StagedCopy() {
        for (cudaEvent_t e : done_)
            if (e) cudaEventDestroy(e);
    }
    StagedCopy(const StagedCopy&) = delete;
    StagedCopy& operator=(const StagedCopy&) = delete;

    /// `bytes` from host memory to the device, on stream 0 (after the work already on it);
    /// returns when the device holds them.
    void to_device(const void* host, void* device, size_t bytes) {
        make_events();
        const char* from = static_cast<const char*>(host);
        char* to = static_cast<char*>(device);
        for (size_t k = 0, offset = 0; offset < bytes; ++k, offset += kChunkBytes) {
            const int b = int(k % 2);
            const size_t n = std::min(kChunkBytes, bytes - offset);
            if (k >= 2) CUDA_CHECK(cudaEventSynchronize(done_[b]));  // the bus is done with this buffer
            char* staging = buffer(b, n);
            host_copy(staging, from + offset, n);
            CUDA_CHECK(cudaMemcpyAsync(to + offset, staging, n, cudaMemcpyHostToDevice, 0));
            CUDA_CHECK(cudaEventRecord(done_[b], 0));
        }
        CUDA_CHECK(cudaStreamSynchronize(0));
    }

    /// `bytes` from the device to host memory, after the work already on stream 0.
    void to_host(const void* device, void* host, size_t bytes) {
        make_events();
        const char* from = static_cast<const char*>(device);
        char* to = static_cast<char*>(host);
        const size_t chunks = (bytes + kChunkBytes - 1) / kChunkBytes;
        for (size_t k = 0; k <= chunks; ++k) {
            if (k < chunks) {  // chunk k starts on the bus ...
                const size_t offset = k * kChunkBytes, n = std::min(kChunkBytes, bytes - offset);
                CUDA_CHECK(cudaMemcpyAsync(buffer(int(k % 2), n), from + offset, n, cudaMemcpyDeviceToHost, 0));
                CUDA_CHECK(cudaEventRecord(done_[k % 2], 0));
            }
            if (k >= 1) {  // ... while chunk k-1 goes to the caller
                const size_t j = k - 1, offset = j * kChunkBytes;
                CUDA_CHECK(cudaEventSynchronize(done_[j % 2]));
                host_copy(to + offset, pinned_[j % 2]->get(), std::min(kChunkBytes, bytes - offset));
            }
        }
    }

    /// Maps the pages of host memory that to_host() will write, by writing a byte in each, on a
    /// few threads: a new NumPy array's pages are mapped at their first write, which costs
    /// more than the copy itself (about 50 against 25 ms for 600 MB). Meant to run on another
    /// thread while the device computes what will be copied there.
    static void map_pages(void* host, size_t bytes) {
        constexpr int64_t kPage = 4096, kBlock = int64_t(16) << 20;
        char* p = static_cast<char*>(host);
        const int threads = std::min(8, resolve_thread_count(0));
        parallel_for(int64_t(bytes), kBlock, threads, [&](int64_t b, int64_t e) {
            for (int64_t i = b; i < e; i += kPage) p[i] = 0;
        });
    }

private:
    /// The events, made at the first copy: on the caller's device then (its sampler has set
    /// it), not on whichever device was current when the sampler was made; made again if a
    /// later copy runs on another device (an event records on its own device's streams only).
    void make_events() {
        const int device = current_device();
        if (device != events_device_) {
            for (cudaEvent_t& e : done_) {
                if (e) cudaEventDestroy(e);
                e = nullptr;
            }
            events_device_ = device;
        }
        for (cudaEvent_t& e : done_)
            if (!e) CUDA_CHECK(cudaEventCreateWithFlags(&e, cudaEventDisableTiming));
    }

    /// Buffer b, at least `need` bytes (at most a chunk): as large as the largest chunk so far,
    /// so that a small copy (a query of a few points) does not pin 64 MB, which takes 15 ms.
    char* buffer(int b, size_t need) {
        constexpr size_t kSmallest = size_t(64) << 10;
        if (!pinned_[b] || pinned_[b]->size() < need) {
            pinned_[b].reset();
            pinned_[b] = std::make_unique<PinnedBytes>(std::min(kChunkBytes, std::max(need, kSmallest)));
        }
        return pinned_[b]->get();
    }

    /// A chunk's host side, on a few threads: one thread copies about 5-10 GB/s, below the bus.
    static void host_copy(void* to, const void* from, size_t n) {
        constexpr int64_t kBlock = int64_t(2) << 20;
        const int threads = std::min(8, resolve_thread_count(0));
        parallel_for(int64_t(n), kBlock, threads, [&](int64_t b, int64_t e) {
            std::memcpy(static_cast<char*>(to) + b, static_cast<const char*>(from) + b, size_t(e - b));
        });
    }

    std::unique_ptr<PinnedBytes> pinned_[2];
    cudaEvent_t done_[2]{};
    int events_device_ = -1;  ///< the device of done_
};

}  // namespace sdf::cuda
