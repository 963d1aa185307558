// DeviceBuffer's memory: stream-ordered allocation from a memory pool of our own on each
// device (cuda/util/device_buffer.h says why).
#include <cuda_runtime.h>

#include <cstdint>
#include <mutex>
#include <vector>

#include "cuda/util/device_buffer.h"

namespace sdf::cuda {
namespace {

/// Freed memory the pool keeps for later allocations, as a fraction of the device's memory:
/// enough for a build and a million-point query, little beside another library's cache.
constexpr uint64_t kPoolKeptDivisor = 16;

/// Per device: its pool, or none where pools are missing (then cudaMalloc/cudaFree).
struct DevicePool {
    bool known = false;
    cudaMemPool_t pool = nullptr;
};

/// `device`'s pool, made on first use; nullptr where the device has no pools. A private pool,
/// not the device's default one: the default pool is the process's, shared with PyTorch's
/// and CuPy's asynchronous allocators and with cuBQL, any of which may set its release
/// threshold; ours keeps what this module chose.
cudaMemPool_t pool_of(int device) {
    // Never destroyed: a buffer freed by another static's destructor at exit still finds them.
    static std::mutex* const mutex = new std::mutex;
    static std::vector<DevicePool>* const pools = new std::vector<DevicePool>;
    std::lock_guard<std::mutex> lock(*mutex);
    if (size_t(device) >= pools->size()) pools->resize(size_t(device) + 1);
    DevicePool& p = (*pools)[size_t(device)];
    if (!p.known) {
        p.known = true;
        int supported = 0;
        size_t free_bytes = 0, total_bytes = 0;
        cudaMemPoolProps props{};
        props.allocType = cudaMemAllocationTypePinned;
        props.handleTypes = cudaMemHandleTypeNone;
        props.location.type = cudaMemLocationTypeDevice;
        props.location.id = device;
        cudaMemPool_t pool = nullptr;
        if (cudaDeviceGetAttribute(&supported, cudaDevAttrMemoryPoolsSupported, device) == cudaSuccess && supported &&
            cudaMemGetInfo(&free_bytes, &total_bytes) == cudaSuccess && cudaMemPoolCreate(&pool, &props) == cudaSuccess) {
            uint64_t keep = uint64_t(total_bytes) / kPoolKeptDivisor;
            if (cudaMemPoolSetAttribute(pool, cudaMemPoolAttrReleaseThreshold, &keep) == cudaSuccess) p.pool = pool;
            else cudaMemPoolDestroy(pool);
        }
        cudaGetLastError();  // a refused query is the fallback, not an error for the next call
    }
    return p.pool;
}

}  // namespace

void* allocate_device_bytes(size_t bytes, int& device) {
    CUDA_CHECK(cudaGetDevice(&device));
    void* ptr = nullptr;
    if (cudaMemPool_t pool = pool_of(device)) CUDA_CHECK(cudaMallocFromPoolAsync(&ptr, bytes, pool, 0));
    else CUDA_CHECK(cudaMalloc(&ptr, bytes));
    return ptr;
}

void free_device_bytes(void* ptr, int device) noexcept {
    int current = device;
    cudaGetDevice(&current);
    if (current != device) cudaSetDevice(device);
    if (pool_of(device)) cudaFreeAsync(ptr, 0);
    else cudaFree(ptr);
    if (current != device) cudaSetDevice(current);
}

size_t free_device_memory() {
    int device = 0;
    CUDA_CHECK(cudaGetDevice(&device));
    size_t free_bytes = 0, total_bytes = 0;
    CUDA_CHECK(cudaMemGetInfo(&free_bytes, &total_bytes));
    if (cudaMemPool_t pool = pool_of(device)) {
        uint64_t reserved = 0, used = 0;
        CUDA_CHECK(cudaMemPoolGetAttribute(pool, cudaMemPoolAttrReservedMemCurrent, &reserved));
        CUDA_CHECK(cudaMemPoolGetAttribute(pool, cudaMemPoolAttrUsedMemCurrent, &used));
        if (reserved > used) free_bytes += size_t(reserved - used);
    }
    return free_bytes;
}

}  // namespace sdf::cuda
