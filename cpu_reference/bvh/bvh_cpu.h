/// @file bvh_cpu.h
/// @brief The CPU BVH sampler (method "bvh"): the exact nearest triangle of every point
/// through the BVH of core/bvh/triangle_bvh.h, then the same double-precision
/// evaluation of the winner as the brute-force sampler (closest point, pseudonormal sign,
/// gradient), so its fields equal brute force to double rounding except at ties.
///
/// Kernels: "brick" (default) queries the 16 points of a lattice brick as one packet that
/// shares a traversal (kernels/bvh/closest_triangles_packet.h), and arbitrary point lists
/// (query) as packets of 16 consecutive points in Morton order, scattered back to input
/// order (the same samples, bit for bit); "seeded" runs the points of a
/// lattice row in order and seeds each query with the previous point's triangle, whose
/// distance is an exact upper bound (kernels/bvh/closest_triangle_bvh.h); "unseeded" starts
/// every query from an infinite radius. Multithreaded with parallel_for; the BVH is built once per mesh and reused.
#pragma once

#include <memory>

#include "core/sampling/kernel_table.h"
#include "core/sampling/sampler.h"

namespace sdf {

enum class CpuBvhKernel { Brick, Seeded, Unseeded };

/// The kernels of method "bvh" on the CPU; the first is the default.
inline constexpr NamedKernel<CpuBvhKernel> kCpuBvhKernels[] = {
    {"brick", CpuBvhKernel::Brick},
    {"seeded", CpuBvhKernel::Seeded},
    {"unseeded", CpuBvhKernel::Unseeded},
};

std::unique_ptr<Sampler> make_cpu_bvh_sampler(const SamplerOptions& options);

}  // namespace sdf
