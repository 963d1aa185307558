#include "cuda/util/cuda_check.h"
#include "cuda/util/cuda_device.h"

#include <string>

namespace sdf::cuda {

int device_count() {
    int n = 0;
    if (cudaGetDeviceCount(&n) != cudaSuccess) {
        cudaGetLastError();  // clear the sticky "no driver" error
        return 0;
    }
    return n;
}

nlohmann::json describe_device(int device) {
    cudaDeviceProp prop{};
    CUDA_CHECK(cudaGetDeviceProperties(&prop, device));
    int driver = 0, runtime = 0;
    CUDA_CHECK(cudaDriverGetVersion(&driver));
    CUDA_CHECK(cudaRuntimeGetVersion(&runtime));
    auto version = [](int v) { return std::to_string(v / 1000) + "." + std::to_string((v % 1000) / 10); };
    char bus[32] = {0};
    CUDA_CHECK(cudaDeviceGetPCIBusId(bus, int(sizeof bus), device));
    return {{"index", device},
            {"name", prop.name},
            {"pci_bus_id", std::string(bus)},
            {"compute_capability", std::to_string(prop.major) + "." + std::to_string(prop.minor)},
            {"multiprocessors", prop.multiProcessorCount},
            {"global_memory_bytes", prop.totalGlobalMem},
            {"l2_cache_bytes", prop.l2CacheSize},
            {"driver_api_version", version(driver)},
            {"runtime_version", version(runtime)}};
}

}  // namespace sdf::cuda
