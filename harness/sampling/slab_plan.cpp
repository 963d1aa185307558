#include "harness/sampling/slab_plan.h"

#include <algorithm>
#include <chrono>
#include <numeric>

#include "core/bvh/triangle_bvh.h"
#include "core/parallel/parallel_for.h"
#include "harness/sampling/sampler_table.h"
#include "kernels/bvh/closest_triangle_bvh.h"

namespace sdf {
namespace {

/// Nodes plus triangles visited, summed over a kPlaneProbes^2 grid of one plane of `block`.
template <typename T>
double probe_plane(const BvhView<T>& view, const Lattice& lattice, const Int3& resolution, int odd, int k) {
    BvhStats stats;
    const int nx = std::min(kPlaneProbes, resolution.x), ny = std::min(kPlaneProbes, resolution.y);
    for (int b = 0; b < ny; ++b)
        for (int a = 0; a < nx; ++a) {
            // Evenly spread lattice points of the plane (integer coordinates, units of h/2).
            const int i = nx > 1 ? int(int64_t(a) * (resolution.x - 1) / (nx - 1)) : 0;
            const int j = ny > 1 ? int(int64_t(b) * (resolution.y - 1) / (ny - 1)) : 0;
            const Vec3d p = lattice.position_of_coords({2 * i + odd, 2 * j + odd, 2 * k + odd});
            closest_triangle_bvh(view, Vec3<T>(p), BvhHit<T>{}, stats);
        }
    return double(stats.nodes + stats.triangles) / double(nx * ny);
}

template <typename T>
std::vector<double> bvh_plane_costs(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& planes) {
    const std::shared_ptr<const TriangleBvh> bvh = mesh.bvh();  // the samplers' tree, built once
    const BvhView<T> view = bvh->view<T>();
    const Int3 r = lattice.resolution, s = lattice.secondary_resolution();
    const bool secondary = lattice.secondary_count() > 0;
    std::vector<double> cost(size_t(r.z), 0.0);
    // Each plane's probes are independent integers: the planes go to every core (a 1024^3
    // plan is 65,536 searches), and the result is the same on any number of threads.
    parallel_for(planes.z_end - planes.z_begin, 8, 0, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
            const int k = planes.z_begin + int(i);
            cost[size_t(k)] = probe_plane(view, lattice, r, 0, k) * double(r.x) * double(r.y);
            if (secondary && k < s.z) cost[size_t(k)] += probe_plane(view, lattice, s, 1, k) * double(s.x) * double(s.y);
        }
    });
    return cost;
}

}  // namespace

double SlabPlan::slab_cost(int rank) const {
    const LatticeSlab& s = slabs[size_t(rank)];
    return std::accumulate(plane_cost.begin() + s.z_begin, plane_cost.begin() + s.z_end, 0.0);
}

double SlabPlan::estimated_max_over_mean() const {
    double max = 0, sum = 0;
    for (int r = 0; r < int(slabs.size()); ++r) {
        max = std::max(max, slab_cost(r));
        sum += slab_cost(r);
    }
    return sum > 0 ? max / (sum / double(slabs.size())) : 1.0;
}

std::vector<double> plane_costs(const PreparedMesh& mesh, const Lattice& lattice, const SamplerOptions& options,
                                std::string& estimate) {
    return plane_costs(mesh, lattice, options, estimate, whole_lattice_slab(lattice));
}

std::vector<double> plane_costs(const PreparedMesh& mesh, const Lattice& lattice, const SamplerOptions& options,
                                std::string& estimate, const LatticeSlab& planes) {
    if (sampler_kind(options).cost == CostModel::BvhVisits && !mesh.triangles().empty()) {
        estimate = "bvh_visits";
        return options.precision == Precision::Float ? bvh_plane_costs<float>(mesh, lattice, planes)
                                                     : bvh_plane_costs<double>(mesh, lattice, planes);
    }
    estimate = "points";
    std::vector<double> cost(size_t(lattice.resolution.z), 0.0);
    for (int k = planes.z_begin; k < planes.z_end; ++k) cost[size_t(k)] = double(slab_point_count(lattice, {k, k + 1}));
    return cost;
}

std::vector<LatticeSlab> balanced_slabs(const std::vector<double>& costs, int parts) {
    const int planes = int(costs.size());
    const double total = std::accumulate(costs.begin(), costs.end(), 0.0);
    std::vector<LatticeSlab> slabs(size_t(std::max(parts, 1)));
    int begin = 0;
    double running = 0;
    for (int r = 0; r < int(slabs.size()); ++r) {
        int end = begin;
        if (r + 1 == int(slabs.size())) {
            end = planes;
        } else {
            const double target = total * double(r + 1) / double(slabs.size());
            // Leave at least one plane for each later part while planes last.
            const int last_allowed = std::max(begin, planes - (int(slabs.size()) - r - 1));
            while (end < last_allowed && (end == begin || running + 0.5 * costs[size_t(end)] < target)) running += costs[size_t(end++)];
        }
        slabs[size_t(r)] = {begin, end};
        begin = end;
    }
    return slabs;
}

SlabPlan plan_slabs(const PreparedMesh& mesh, const Lattice& lattice, const SamplerOptions& options, int parts) {
    const auto start = std::chrono::steady_clock::now();
    SlabPlan plan;
    plan.plane_cost = plane_costs(mesh, lattice, options, plan.estimate);
    plan.slabs = balanced_slabs(plan.plane_cost, parts);
    plan.estimate_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return plan;
}

}  // namespace sdf
