/// @file slab_plan.h
/// @brief How a distributed run cuts a lattice into one slab per rank, and a process its
/// slabs over its GPUs (multi_device_sampler.h),
/// (kernels/lattice/lattice_slab.h), balanced by an estimate of each z-plane's cost.
///
/// Brute force costs the same at every point (every triangle is tested), so a plane costs
/// its point count. A BVH query does not: it depends on how many nodes and triangles the
/// search visits, which varies across the lattice (far from the surface many triangles are
/// nearly equidistant). The estimate runs the BVH query on a coarse grid of each plane
/// (kPlaneProbes per axis) and counts the nodes and triangles visited. The counts are
/// integers from a deterministic build and traversal, so the plan is the same on every rank
/// and every machine; the root computes it and sends it with the request all the same.
#pragma once

#include <string>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "core/sampling/sampler.h"
#include "kernels/lattice/lattice_slab.h"

namespace sdf {

/// Probe points per axis of each plane for the BVH cost estimate.
constexpr int kPlaneProbes = 8;

struct SlabPlan {
    std::vector<double> plane_cost;   ///< estimated cost of each primary z-plane (with its secondary plane)
    std::vector<LatticeSlab> slabs;   ///< one per rank, contiguous, in rank order
    std::string estimate;             ///< "points" (brute force) or "bvh_visits"
    double estimate_seconds = 0;

    double slab_cost(int rank) const;
    /// Largest slab cost over the mean (1 = perfect balance).
    double estimated_max_over_mean() const;
};

/// Estimated cost of each primary z-plane of `lattice` for a sampler with `options`.
std::vector<double> plane_costs(const PreparedMesh& mesh, const Lattice& lattice, const SamplerOptions& options,
                                std::string& estimate);

/// The same for the planes of `planes` only (the others cost 0): a slab cut over devices.
std::vector<double> plane_costs(const PreparedMesh& mesh, const Lattice& lattice, const SamplerOptions& options,
                                std::string& estimate, const LatticeSlab& planes);

/// Cuts planes [0, costs.size()) into `parts` contiguous slabs of about equal cost: slab r
/// ends where the running cost first reaches (r + 1) / parts of the total. Slabs are empty
/// only when there are more parts than planes.
std::vector<LatticeSlab> balanced_slabs(const std::vector<double>& costs, int parts);

/// Both steps, timed.
SlabPlan plan_slabs(const PreparedMesh& mesh, const Lattice& lattice, const SamplerOptions& options, int parts);

}  // namespace sdf
