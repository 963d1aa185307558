/// @file cpu_isa.h
/// @brief The x86-64 micro-architecture levels (psABI x86-64-v2, -v3, -v4) the hot CPU
/// kernels are compiled for, and whether this CPU runs them.
///
/// A portable build runs everywhere at x86-64-v2 but compiles the search loops once per level
/// (cpu_kernels.h) and runs the widest the CPU supports: the loops vectorise well only with
/// AVX-512's masked operations (docs/architecture-floating-point.md).
#pragma once

#include <string>

namespace sdf {

enum class CpuIsa { X86_64_V2 = 2, X86_64_V3 = 3, X86_64_V4 = 4 };

/// The levels, narrowest first.
inline constexpr CpuIsa kCpuIsaLevels[] = {CpuIsa::X86_64_V2, CpuIsa::X86_64_V3, CpuIsa::X86_64_V4};

/// "x86-64-v2", "x86-64-v3", "x86-64-v4" (GCC's -march names).
const char* cpu_isa_name(CpuIsa isa);

/// Whether this CPU and its operating system run code of level `isa` (cpuid and the enabled
/// register state, through the compiler's __builtin_cpu_supports).
bool cpu_supports(CpuIsa isa);

/// A level from "v2", "v3", "v4" or the full names; anything else throws, naming `where`
/// (e.g. "environment variable SDF_CPU_ISA") and the accepted values.
CpuIsa parse_cpu_isa(const std::string& text, const std::string& where);

}  // namespace sdf
