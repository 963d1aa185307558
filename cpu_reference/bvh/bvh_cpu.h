/// @file bvh_cpu.h
/// @brief The CPU BVH sampler (method "bvh"): the exact nearest triangle of every point
/// through the BVH of cpu_reference/bvh/triangle_bvh.h, then the same double-precision
/// evaluation of the winner as the brute-force sampler (closest point, pseudonormal sign,
/// gradient), so its fields equal brute force to double rounding except at ties.
///
/// Kernels: "seeded" (default) runs the points of a lattice row in order and seeds each
/// query with the previous point's triangle, whose distance is an exact upper bound (see
/// kernels/bvh/closest_triangle_bvh.h); "unseeded" starts every query from an infinite
/// radius. Multithreaded with parallel_for; the BVH is built once per mesh and reused.
#pragma once

#include <memory>

#include "core/sampling/sampler.h"

namespace sdf {

std::unique_ptr<Sampler> make_cpu_bvh_sampler(const SamplerOptions& options);

}  // namespace sdf
