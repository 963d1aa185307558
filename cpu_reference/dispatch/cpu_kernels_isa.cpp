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
#include "cpu_reference/dispatch/rerank_simd.h"

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

/// rerank_in_double() for BVH slots (`triangle_index` maps them to triangles) or, with
/// `triangle_index` null, for triangle indices (the brute force's); its vector form
/// (rerank_simd.h), the same winner.
Rerank rerank(const PackedTriangle<double>* exact, const int32_t* triangle_index, const Vec3d& p, int32_t winner,
              float radius, const int32_t* slot, const float* q, int count, float dropped) {
    if (triangle_index == nullptr)
        return rerank_in_double_simd(exact, [](int32_t s) { return s; }, p.x, p.y, p.z, winner, radius, slot, q, count,
                                     dropped);
    return rerank_in_double_simd(exact, [triangle_index](int32_t s) { return triangle_index[s]; }, p.x, p.y, p.z, winner,
                                 radius, slot, q, count, dropped);
}

template <typename T>
constexpr CpuKernels<T> kernels_of() {
    using Table = CpuKernels<T>;
    return {&Flattened<static_cast<decltype(Table::nearest_triangles)>(&nearest_triangles_vectorized<T>)>::call,
            &Flattened<static_cast<decltype(Table::closest_triangles_packet)>(
                &closest_triangles_packet<T, kCpuPacketLanes, BvhStats>)>::call,
            &Flattened<static_cast<decltype(Table::closest_triangle)>(&closest_triangle_bvh<T, BvhStats>)>::call,
            &Flattened<&nearest_triangle_eberly<T>>::call};
}

constexpr CpuCertifiedKernels certified_kernels() {
    using Table = CpuCertifiedKernels;
    using Packet = CpuPacketCertifiedNear;
    return {&Flattened<static_cast<decltype(Table::nearest_triangles)>(
                &nearest_triangles_vectorized<float, CpuCertifiedNear>)>::call,
            &Flattened<static_cast<decltype(Table::nearest_triangles_all)>(&nearest_triangles_vectorized<float, AllNear>)>::call,
            &Flattened<static_cast<decltype(Table::closest_triangles_packet)>(
                &closest_triangles_packet<float, kCpuPacketLanes, BvhStats, Packet>)>::call,
            &Flattened<static_cast<decltype(Table::closest_triangle)>(
                &closest_triangle_bvh<float, BvhStats, CpuCertifiedNear>)>::call,
            &Flattened<static_cast<decltype(Table::closest_triangle_all)>(&closest_triangle_bvh<float, BvhStats, AllNear>)>::call,
            &Flattened<&rerank>::call};
}

constexpr CpuKernelSet kSet{SDF_CPU_KERNEL_ISA, kernels_of<float>(), kernels_of<double>(), certified_kernels(),
                            &Flattened<&fast_winding_numbers_packet<kCpuPacketLanes>>::call,
                            &Flattened<&certified_winding_sides_packet<kCpuPacketLanes>>::call,
                            &Flattened<&sweep_band_block>::call};

}  // namespace

const CpuKernelSet& SDF_CPU_KERNEL_SET() { return kSet; }

}  // namespace sdf
