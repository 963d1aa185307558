#include "harness/sampling/sampler_table.h"

#include <algorithm>
#include <stdexcept>

#include "core/sampling/kernel_table.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "cuda/bvh/bvh_sampler.h"
#include "cuda/brute_force/cuda_sampler.h"
#include "harness/build_config.h"
#include "harness/sampling/device_selection.h"
#include "harness/sampling/multi_device_sampler.h"
#include "harness/sampling/streamed_sampling.h"
#if SDF_HAVE_CUDA
#include "cuda/util/cuda_device.h"
#endif

namespace sdf {

namespace {
#if SDF_HAVE_CUDA
constexpr auto kCudaBruteForce = cuda::make_cuda_brute_force_sampler;
constexpr auto kCudaBvh = cuda::make_cuda_bvh_sampler;
#else
constexpr std::unique_ptr<Sampler> (*kCudaBruteForce)(const SamplerOptions&) = nullptr;
constexpr std::unique_ptr<Sampler> (*kCudaBvh)(const SamplerOptions&) = nullptr;
#endif

void add_unique(std::vector<std::string>& list, const char* name) {
    if (std::find(list.begin(), list.end(), name) == list.end()) list.emplace_back(name);
}
}  // namespace

const std::vector<SamplerKind>& sampler_table() {
    static const std::vector<SamplerKind> table = {
        {"cpu", "brute_force", kernel_names(kCpuBruteForceKernels), make_cpu_brute_force_sampler,
         false, kStreamBytesPerPoint, CostModel::PerPoint},
        {"cpu", "bvh", kernel_names(kCpuBvhKernels), make_cpu_bvh_sampler,
         false, kStreamBytesPerPoint, CostModel::BvhVisits},
        {"cuda", "brute_force", kernel_names(cuda::kCudaBruteForceKernels), kCudaBruteForce,
         true, kStreamBytesPerPointCuda, CostModel::PerPoint},
        {"cuda", "bvh", kernel_names(cuda::kCudaBvhKernels), kCudaBvh,
         true, kStreamBytesPerPointCuda, CostModel::BvhVisits},
    };
    return table;
}

std::vector<std::string> sampler_backends() {
    std::vector<std::string> names;
    for (const SamplerKind& k : sampler_table()) add_unique(names, k.backend);
    return names;
}

std::string resolve_sampler_backend(const std::string& backend) {
    if (backend != "auto") return backend;
    return cuda_backend_available() ? "cuda" : "cpu";
}

std::vector<std::string> sampler_backend_choices() {
    std::vector<std::string> names = {"auto"};
    for (const std::string& b : sampler_backends()) names.push_back(b);
    return names;
}

std::vector<std::string> sampler_methods() {
    std::vector<std::string> names;
    for (const SamplerKind& k : sampler_table()) add_unique(names, k.method);
    return names;
}

const SamplerKind& sampler_kind(const std::string& backend, const std::string& method) {
    const std::vector<std::string> backends = sampler_backends();
    if (std::find(backends.begin(), backends.end(), backend) == backends.end())
        throw std::invalid_argument("sampler.backend: unknown backend '" + backend + "'; expected " +
                                    quoted_alternatives(backends));
    for (const SamplerKind& k : sampler_table())
        if (backend == k.backend && method == k.method) return k;
    throw std::invalid_argument("sampler.method: backend '" + backend + "' has no method '" + method + "'; expected " +
                                quoted_alternatives(sampler_methods()));
}

const SamplerKind& sampler_kind(const SamplerOptions& options) {
    return sampler_kind(resolve_sampler_backend(options.backend), options.method);
}

void check_sampler_kernel(const SamplerOptions& options) {
    const SamplerKind& kind = sampler_kind(options);
    if (options.kernel.empty() ||
        std::find(kind.kernels.begin(), kind.kernels.end(), options.kernel) != kind.kernels.end())
        return;
    throw std::invalid_argument("sampler.kernel: unknown " + std::string(kind.backend) + " " + kind.method +
                                " kernel '" + options.kernel + "'; expected " + quoted_alternatives(kind.kernels));
}

bool cuda_backend_available() {
#if SDF_HAVE_CUDA
    return cuda::device_count() > 0;
#else
    return false;
#endif
}

std::unique_ptr<Sampler> make_sampler(const SamplerOptions& options) {
    SamplerOptions resolved = options;
    resolved.backend = resolve_sampler_backend(options.backend);
    const SamplerKind& kind = sampler_kind(resolved);
    check_sampler_kernel(resolved);
    if (kind.make == nullptr)
        throw std::runtime_error("sampler.backend \"" + resolved.backend +
                                 "\": this build has no CUDA backend (configure with nvcc available and "
                                 "SDF_ENABLE_CUDA=AUTO or ON)");
    if (kind.on_gpu && !cuda_backend_available())
        throw std::runtime_error("sampler.backend \"" + resolved.backend + "\": no CUDA device is present on this machine");
    if (!kind.on_gpu) {
        // The CPU samplers use the host's threads; "all" GPUs of a machine without one (the
        // backend "auto" resolved to cpu) asks for nothing more, a list of GPUs for what
        // this backend cannot do.
        if (!resolved.devices.all && !resolved.devices.list.empty())
            throw std::invalid_argument("sampler.devices: a list of CUDA devices needs the backend cuda; the backend is \"" +
                                        resolved.backend + "\"");
        resolved.devices = DeviceSelection{};
        return kind.make(resolved);
    }
#if SDF_HAVE_CUDA
    const std::vector<int> devices = resolve_devices(resolved, cuda::device_count());
    if (devices.size() == 1) {
        resolved.device = devices[0];
        resolved.devices = DeviceSelection{};
        return kind.make(resolved);
    }
    return make_multi_device_sampler(resolved, devices, kind.make, [](int device) { return cuda::describe_device(device); });
#else
    return kind.make(resolved);
#endif
}

int sampler_device_count(const SamplerOptions& options) {
    if (!sampler_kind(options).on_gpu || options.devices.is_default()) return 1;
#if SDF_HAVE_CUDA
    return int(resolve_devices(options, cuda::device_count()).size());
#else
    return 1;
#endif
}

}  // namespace sdf
