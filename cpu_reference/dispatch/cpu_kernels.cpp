#include "cpu_reference/dispatch/cpu_kernels.h"

#include <cstdlib>
#include <iterator>
#include <stdexcept>
#include <string>

namespace sdf {

// The sets compiled by cpu_kernels_isa.cpp (cpu_reference/CMakeLists.txt says which).
#if SDF_CPU_DISPATCH
const CpuKernelSet& cpu_kernels_x86_64_v2();
const CpuKernelSet& cpu_kernels_x86_64_v3();
const CpuKernelSet& cpu_kernels_x86_64_v4();
#else
const CpuKernelSet& cpu_kernels_build_target();
#endif

namespace {

constexpr const char* kIsaVariable = "SDF_CPU_ISA";

#if SDF_CPU_DISPATCH
const CpuKernelSet& built_set(CpuIsa isa) {
    switch (isa) {
        case CpuIsa::X86_64_V2: return cpu_kernels_x86_64_v2();
        case CpuIsa::X86_64_V3: return cpu_kernels_x86_64_v3();
        case CpuIsa::X86_64_V4: break;
    }
    return cpu_kernels_x86_64_v4();
}
#endif

struct Choice {
    const CpuKernelSet* set;
    const char* chosen_by;
};

const Choice& choice() {
    static const Choice c = [] {
        const char* requested = std::getenv(kIsaVariable);
        const std::string r = requested != nullptr ? requested : "";
        const CpuKernelSet& set = select_cpu_kernels(r);
        return Choice{&set, SDF_CPU_DISPATCH ? (r.empty() ? "cpu" : kIsaVariable) : "build target"};
    }();
    return c;
}

}  // namespace

const CpuKernelSet& select_cpu_kernels(const std::string& requested) {
    const std::string where = std::string("environment variable ") + kIsaVariable + "=" + requested;
#if SDF_CPU_DISPATCH
    if (!requested.empty()) {
        const CpuIsa isa = parse_cpu_isa(requested, where);
        if (!cpu_supports(isa))
            throw std::runtime_error(where + ": this CPU cannot run " + cpu_isa_name(isa) +
                                     " code; choose a narrower level or unset it");
        return built_set(isa);
    }
    for (int i = int(std::size(kCpuIsaLevels)) - 1; i > 0; --i)
        if (cpu_supports(kCpuIsaLevels[i])) return built_set(kCpuIsaLevels[i]);
    return built_set(CpuIsa::X86_64_V2);  // the build's own target: runs wherever the program runs
#else
    if (!requested.empty())
        throw std::runtime_error(where + ": this build compiles its kernels once, for SDF_CPU_TARGET=" SDF_CPU_TARGET_OPTION
                                 "; only a portable build (the default) holds one set per level");
    return cpu_kernels_build_target();
#endif
}

const CpuKernelSet& active_cpu_kernels() { return *choice().set; }

const CpuKernelSet* cpu_kernel_set(CpuIsa isa) {
#if SDF_CPU_DISPATCH
    return cpu_supports(isa) ? &built_set(isa) : nullptr;
#else
    (void)isa;
    return nullptr;
#endif
}

CpuKernelChoice cpu_kernel_choice() {
    CpuKernelChoice c{choice().set->isa, choice().chosen_by, {}};
#if SDF_CPU_DISPATCH
    for (CpuIsa isa : kCpuIsaLevels) c.built.push_back(cpu_isa_name(isa));
#else
    c.built.push_back(cpu_kernels_build_target().isa);
#endif
    return c;
}

}  // namespace sdf
