/// @file cpu_kernels.h
/// @brief Run-time dispatch of the hot CPU search loops to the widest ISA the CPU has.
///
/// The loops (the vectorised and the Eberly brute force, the BVH point and packet
/// traversals of kernels/bvh, in their plain and certified forms, the certified search's
/// re-ranking in double, the packet of fast winding numbers, the packet of certified
/// winding sides and the sparse band's block sweep) are compiled once per ISA level by cpu_kernels_isa.cpp into a
/// CpuKernelSet of function pointers; the samplers call them through cpu_kernels<T>() and
/// certified_cpu_kernels(), which use the set chosen once per process: the widest level this
/// CPU supports, or the one the environment variable SDF_CPU_ISA (v2, v3, v4) forces. Every
/// level is compiled with -ffp-contract=off, so all return the same bits
/// (tests/cpu_reference/dispatch/cpu_isa_test.cpp). A build for one target (SDF_CPU_TARGET
/// other than portable) holds a single set, compiled for it.
#pragma once

#include <string>
#include <type_traits>
#include <vector>

#include "cpu_reference/dispatch/cpu_isa.h"
#include "cpu_reference/sampling/nearest_triangle_cpu.h"
#include "kernels/bvh/closest_triangle_bvh.h"
#include "kernels/bvh/closest_triangles_packet.h"
#include "kernels/distance/search_certificate.h"
#include "kernels/distance/signed_distance.h"
#include "kernels/lattice/band_sweep.h"
#include "kernels/winding/certified_winding_packet.h"
#include "kernels/winding/fast_winding_packet.h"

namespace sdf {

/// Points per BVH packet: lattice bricks of 4 x 2 x 2 and Morton runs of arbitrary points (16
/// float lanes: one AVX-512 register, or two AVX2 registers, per coordinate in the leaf loop).
constexpr int kCpuPacketLanes = 16;

/// Candidates a certified CPU search keeps per point: twice the GPU's kNearCandidates. At a
/// vertex of more than 8 triangles every one ties; with 8 slots 2.4% of the dragon-legacy
/// 64^3 lattice's points overflowed into a second, unbounded search (AllNear).
constexpr int kCpuNearCandidates = 16;
using CpuCertifiedNear = CertifiedNear<float, kCpuNearCandidates>;
using CpuPacketCertifiedNear = PacketCertifiedNear<float, kCpuPacketLanes, kCpuNearCandidates>;

/// Every candidate of a certified float search, without a limit: the fallback for a point
/// with more candidates than NearCandidates keeps (search_certificate.h).
struct AllNear {
    static constexpr bool kKeeps = true;
    SearchSlack<float> slack;
    std::vector<int32_t> slot;
    std::vector<float> q;
    float radius(float v) const { return slack.radius(v); }
    void offer(int32_t s, float v) {
        slot.push_back(s);
        q.push_back(v);
    }
};

/// The kernels' signatures (nearest_triangle_cpu.h, closest_triangle_bvh.h,
/// closest_triangles_packet.h) with the `Near` policy that decides what a search keeps.
template <typename T, typename Near>
using NearestTrianglesFn = void (*)(const TriangleSoA<T>& soa, int count, const T* px, const T* py, const T* pz,
                                    int* best_index, T* best_q, Near* near);
template <typename T, typename Near>
using ClosestTriangleFn = BvhHit<T> (*)(const BvhView<T>& bvh, const Vec3<T>& p, BvhHit<T> best, BvhStats& stats, Near& near);
template <typename T, typename Near>
using ClosestTrianglesPacketFn = void (*)(const BvhView<T>& bvh, BvhPacket<T, kCpuPacketLanes>& pk, BvhStats& stats,
                                          Near& near);

/// rerank_in_double() (search_certificate.h) at p for candidates given as BVH slots
/// (`triangle_index`: the BVH's slot-to-triangle map, for the tie rule) or, with
/// `triangle_index` null, as triangle indices.
using RerankFn = Rerank (*)(const PackedTriangle<double>* exact, const int32_t* triangle_index, const Vec3d& p,
                            int32_t winner, float radius, const int32_t* slot, const float* q, int count, float dropped);

/// The plain searches of one ISA level for search precision T (double: the reference; float:
/// uncertified, e.g. the narrow band's probes, which need only a distance bound).
template <typename T>
struct CpuKernels {
    void (*nearest_triangles)(const TriangleSoA<T>& soa, int count, const T* px, const T* py, const T* pz,
                              int* best_index, T* best_q);
    void (*closest_triangles_packet)(const BvhView<T>& bvh, BvhPacket<T, kCpuPacketLanes>& pk, BvhStats& stats);
    BvhHit<T> (*closest_triangle)(const BvhView<T>& bvh, const Vec3<T>& p, BvhHit<T> best, BvhStats& stats);
    int (*nearest_triangle_eberly)(const MeshView<T>& mesh, const Vec3<T>& p);  ///< the thesis's kernel, one point
};

/// The certified float search of one ISA level (search_certificate.h): the searches that keep
/// their candidates, the fallbacks that keep every one, and the re-ranking in double.
struct CpuCertifiedKernels {
    NearestTrianglesFn<float, CpuCertifiedNear> nearest_triangles;
    NearestTrianglesFn<float, AllNear> nearest_triangles_all;  ///< one point: count 1
    ClosestTrianglesPacketFn<float, CpuPacketCertifiedNear> closest_triangles_packet;
    ClosestTriangleFn<float, CpuCertifiedNear> closest_triangle;
    ClosestTriangleFn<float, AllNear> closest_triangle_all;
    RerankFn rerank;
};

/// fast_winding_numbers_packet() (fast_winding_packet.h) for a packet of kCpuPacketLanes points.
using WindingPacketFn = void (*)(const WindingView<double>& v, const double* px, const double* py, const double* pz,
                                 const WindingAccuracy<double>& acc, double* value);

/// certified_winding_sides_packet() (certified_winding_packet.h) for kCpuPacketLanes points.
using CertifiedWindingPacketFn = void (*)(const WindingView<double>& v, const Vec3d* p, int count,
                                          const WindingAccuracy<double>& acc, const WindingCertification& cert,
                                          WindingSide* side);

/// sweep_band_block() (band_sweep.h): a sparse band block's nearest triangles within a bound.
using SweepBandBlockFn = void (*)(const PackedTriangle<double>* packed, const int32_t* triangle_index, const int32_t* slots,
                                  int count, const BandSweepBlock& block, double bound_squared, double* best_q,
                                  int32_t* best_triangle);

struct CpuKernelSet {
    const char* isa;  ///< "x86-64-v4", or the build's -march value in a single-target build
    CpuKernels<float> float_kernels;
    CpuKernels<double> double_kernels;
    CpuCertifiedKernels certified;
    WindingPacketFn winding_numbers_packet;
    CertifiedWindingPacketFn winding_sides_packet;
    SweepBandBlockFn sweep_band_block;

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

inline const CpuCertifiedKernels& certified_cpu_kernels() { return active_cpu_kernels().certified; }

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
