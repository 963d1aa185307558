// The hot loops compiled for one ISA level: CMake builds this file once per level
// (cpu_reference/CMakeLists.txt, -march=<level>), defining SDF_CPU_KERNEL_SET (the accessor's
// name) and SDF_CPU_KERNEL_ISA (the level's name).
//
// The kernels are inline templates shared with every other file. Compiled here for x86-64-v4,
// an out-of-line copy would be a weak symbol of the same name as the x86-64-v2 copy elsewhere,
// and the linker could keep this one for the whole program (a crash on a CPU without
// AVX-512). So each entry point is flattened (every call inlined into it) and has internal
// linkage: this object defines one global symbol, the accessor, and CTest checks that
// (scripts/check-isa-objects).
#include "cpu_reference/dispatch/cpu_kernels.h"

#if !defined(SDF_CPU_KERNEL_SET) || !defined(SDF_CPU_KERNEL_ISA)
#error "cpu_kernels_isa.cpp is compiled by CMake once per ISA level, with SDF_CPU_KERNEL_SET and SDF_CPU_KERNEL_ISA"
#endif

namespace sdf {
namespace {

/// Kernel F compiled into this object: a local function with F's signature and F's body.
template <auto F>
struct Flattened;
template <typename R, typename... Args, R (*F)(Args...)>
struct Flattened<F> {
    [[gnu::flatten]] static R call(Args... args) { return F(static_cast<Args&&>(args)...); }
};

template <typename T>
constexpr decltype(CpuKernels<T>::closest_triangle) kClosestTriangle = &closest_triangle_bvh<T, BvhStats>;

template <typename T>
constexpr CpuKernels<T> kernels_of() {
    return {&Flattened<&nearest_triangles_vectorized<T>>::call,
            &Flattened<&closest_triangles_packet<T, kCpuPacketLanes, BvhStats>>::call,
            &Flattened<kClosestTriangle<T>>::call};
}

constexpr CpuKernelSet kSet{SDF_CPU_KERNEL_ISA, kernels_of<float>(), kernels_of<double>()};

}  // namespace

const CpuKernelSet& SDF_CPU_KERNEL_SET() { return kSet; }

}  // namespace sdf
