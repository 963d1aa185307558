#include "harness/sampling/make_sampler.h"

#include <stdexcept>

#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "harness/build_config.h"
#if SDF_HAVE_CUDA
#include "cuda/cuda_device.h"
#include "cuda/bvh_sampler.h"
#include "cuda/cuda_sampler.h"
#endif

namespace sdf {

bool cuda_backend_available() {
#if SDF_HAVE_CUDA
    return cuda::device_count() > 0;
#else
    return false;
#endif
}

std::unique_ptr<Sampler> make_sampler(const SamplerOptions& options) {
    if (options.backend == "cpu") {
        if (options.method == "brute_force") return make_cpu_brute_force_sampler(options);
        if (options.method == "bvh") return make_cpu_bvh_sampler(options);
    } else if (options.backend == "cuda") {
#if SDF_HAVE_CUDA
        if (!cuda_backend_available())
            throw std::runtime_error("sampler.backend \"cuda\": no CUDA device is present on this machine");
        if (options.method == "brute_force") return cuda::make_cuda_brute_force_sampler(options);
        if (options.method == "bvh") return cuda::make_cuda_bvh_sampler(options);
#else
        throw std::runtime_error("sampler.backend \"cuda\": this build has no CUDA backend (configure with nvcc "
                                 "available and SDF_ENABLE_CUDA=AUTO or ON)");
#endif
    } else {
        throw std::invalid_argument("sampler.backend: unknown backend '" + options.backend + "'; expected \"cpu\" or \"cuda\"");
    }
    throw std::invalid_argument("sampler.method: backend '" + options.backend + "' has no method '" + options.method + "'");
}

}  // namespace sdf
