// DeviceBuffer's memory: stream-ordered allocation from each device's default pool
// (cuda/device_buffer.h says why).
#include <cuda_runtime.h>

#include <cstdint>
#include <mutex>
#include <vector>

#include "cuda/device_buffer.h"

namespace sdf::cuda {
namespace {

/// Freed memory the pool keeps for later allocations, as a fraction of the device's memory:
/// enough for a build and a million-point query, little beside another library's cache.
constexpr uint64_t kPoolKeptDivisor = 16;

/// Whether `device` allocates from its pool; the pool's release threshold is set on first use.
bool pool_ready(int device) {
    // Never destroyed: a buffer freed by another static's destructor at exit still finds them.
    static std::mutex* const mutex = new std::mutex;
    static std::vector<int>* const state = new std::vector<int>;  // per device: 0 unknown, 1 pool, 2 no pool
    std::lock_guard<std::mutex> lock(*mutex);
    if (size_t(device) >= state->size()) state->resize(size_t(device) + 1, 0);
    int& s = (*state)[size_t(device)];
    if (s == 0) {
        int supported = 0;
        cudaMemPool_t pool{};
        size_t free_bytes = 0, total_bytes = 0;
        s = 2;
        if (cudaDeviceGetAttribute(&supported, cudaDevAttrMemoryPoolsSupported, device) == cudaSuccess && supported &&
            cudaDeviceGetDefaultMemPool(&pool, device) == cudaSuccess && cudaMemGetInfo(&free_bytes, &total_bytes) == cudaSuccess) {
            uint64_t keep = uint64_t(total_bytes) / kPoolKeptDivisor;
            if (cudaMemPoolSetAttribute(pool, cudaMemPoolAttrReleaseThreshold, &keep) == cudaSuccess) s = 1;
        }
        cudaGetLastError();  // a refused query is the fallback, not an error for the next call
    }
    return s == 1;
}

}  // namespace

void* allocate_device_bytes(size_t bytes, int& device) {
    CUDA_CHECK(cudaGetDevice(&device));
    void* ptr = nullptr;
    if (pool_ready(device)) CUDA_CHECK(cudaMallocAsync(&ptr, bytes, 0));
    else CUDA_CHECK(cudaMalloc(&ptr, bytes));
    return ptr;
}

void free_device_bytes(void* ptr, int device) noexcept {
    int current = device;
    cudaGetDevice(&current);
    if (current != device) cudaSetDevice(device);
    if (pool_ready(device)) cudaFreeAsync(ptr, 0);
    else cudaFree(ptr);
    if (current != device) cudaSetDevice(current);
}

}  // namespace sdf::cuda
