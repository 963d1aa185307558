/// @file cpu_kernels.h
/// @brief Run-time dispatch of the hot CPU search loops to the widest ISA the CPU has.
///
/// The loops (the vectorised brute force of nearest_triangle_cpu.h, the BVH point and packet
/// traversals of kernels/bvh) are compiled once per ISA level by cpu_kernels_isa.cpp into a
/// CpuKernelSet of function pointers; the samplers call them through cpu_kernels<T>(), which
/// is chosen once per process: the widest level this CPU supports, or the one the environment
/// variable SDF_CPU_ISA (v2, v3, v4) forces. Every level is compiled with -ffp-contract=off,
/// so all return the same bits (tests/cpu_reference/dispatch/cpu_isa_test.cpp). A build for
/// one target (SDF_CPU_TARGET other than portable) holds a single set, compiled for it.
#pragma once

#include <string>
#include <type_traits>
#include <vector>

#include "cpu_reference/dispatch/cpu_isa.h"
#include "cpu_reference/sampling/nearest_triangle_cpu.h"
#include "kernels/bvh/closest_triangle_bvh.h"
#include "kernels/bvh/closest_triangles_packet.h"

namespace sdf {

/// Points per BVH packet: lattice bricks of 4 x 2 x 2 and Morton runs of arbitrary points (16
/// float lanes: one AVX-512 register, or two AVX2 registers, per coordinate in the leaf loop).
constexpr int kCpuPacketLanes = 16;

/// The hot loops of one ISA level for search precision T. The types follow the kernels'
/// own signatures, so the table changes with them.
template <typename T>
struct CpuKernels {
    decltype(&nearest_triangles_vectorized<T>) nearest_triangles;
    decltype(&closest_triangles_packet<T, kCpuPacketLanes, BvhStats>) closest_triangles_packet;
    BvhHit<T> (*closest_triangle)(const BvhView<T>& bvh, const Vec3<T>& p, BvhHit<T> best, BvhStats& stats);
};

struct CpuKernelSet {
    const char* isa;  ///< "x86-64-v4", or the build's -march value in a single-target build
    CpuKernels<float> float_kernels;
    CpuKernels<double> double_kernels;

    template <typename T>
    const CpuKernels<T>& get() const {
        if constexpr (std::is_same_v<T, float>) return float_kernels;
        else return double_kernels;
    }
};

/// The set this process runs (chosen on the first call; throws when SDF_CPU_ISA names a level
/// that is not built or that this CPU lacks). Samplers call it when they are made, so a bad
/// SDF_CPU_ISA is reported before any work.
const CpuKernelSet& active_cpu_kernels();

/// The set that SDF_CPU_ISA=`requested` selects ("": the widest level the CPU supports);
/// throws as active_cpu_kernels() does. active_cpu_kernels() is this for the environment.
const CpuKernelSet& select_cpu_kernels(const std::string& requested);

template <typename T>
const CpuKernels<T>& cpu_kernels() {
    return active_cpu_kernels().get<T>();
}

/// The set of one level, or nullptr when this build did not compile it or this CPU cannot
/// run it (for tests and benchmarks comparing levels).
const CpuKernelSet* cpu_kernel_set(CpuIsa isa);

/// Which kernels run, for the manifests' build record (harness/provenance).
struct CpuKernelChoice {
    std::string isa;                 ///< the level that runs (CpuKernelSet::isa)
    std::string chosen_by;           ///< "cpu" (the widest it supports), "SDF_CPU_ISA" or "build target"
    std::vector<std::string> built;  ///< the levels this build compiled
};
CpuKernelChoice cpu_kernel_choice();

}  // namespace sdf
