#include "cpu_reference/dispatch/cpu_isa.h"

#include <stdexcept>

namespace sdf {

const char* cpu_isa_name(CpuIsa isa) {
    switch (isa) {
        case CpuIsa::X86_64_V2: return "x86-64-v2";
        case CpuIsa::X86_64_V3: return "x86-64-v3";
        case CpuIsa::X86_64_V4: return "x86-64-v4";
    }
    return "unknown";
}

bool cpu_supports(CpuIsa isa) {
#if defined(__x86_64__) && defined(__GNUC__)
    // libgcc's check includes the operating system's XSAVE state (AVX and AVX-512 registers
    // enabled), not only the cpuid bits.
    __builtin_cpu_init();
    switch (isa) {
        case CpuIsa::X86_64_V2: return __builtin_cpu_supports("x86-64-v2");
        case CpuIsa::X86_64_V3: return __builtin_cpu_supports("x86-64-v3");
        case CpuIsa::X86_64_V4: return __builtin_cpu_supports("x86-64-v4");
    }
#endif
    (void)isa;
    return false;
}

CpuIsa parse_cpu_isa(const std::string& text, const std::string& where) {
    for (CpuIsa isa : kCpuIsaLevels) {
        const std::string name = cpu_isa_name(isa);
        if (text == name || text == name.substr(name.size() - 2)) return isa;
    }
    throw std::runtime_error(where + ": expected one of v2, v3, v4 (or x86-64-v2, x86-64-v3, x86-64-v4), got \"" + text + "\"");
}

}  // namespace sdf
