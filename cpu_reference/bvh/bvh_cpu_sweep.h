/// @file bvh_cpu_sweep.h
/// @brief The CPU BVH sampler's triangle sweep of a sparse band block (a solid's pseudonormal
/// band at least a spacing wide, kernels/lattice/band_sweep.h): the block's triangles by a box
/// query of the BVH, their nearest points by the vectorised sweep, then each point with a
/// triangle finalized as the dense path finalizes it, and each point without one handed over
/// beyond the band (its side from its neighbours, band_sides.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "cpu_reference/dispatch/cpu_kernels.h"
#include "kernels/bvh/box_query.h"
#include "kernels/lattice/band_sides.h"
#include "kernels/lattice/band_sweep.h"
#include "kernels/lattice/sampling_grid.h"

namespace sdf::cpu_bvh {

/// A thread's arrays for sweep_block (reused from block to block).
struct SweepScratch {
    std::vector<int32_t> slots;
    std::vector<std::pair<double, int32_t>> order;
    double best_q[kBandBlockPoints];
    int32_t best_triangle[kBandBlockPoints];
};

/// Sweeps `block` (one band block: step 2, at most 8 points per axis) with the bound
/// `bound_squared` (band_sweep_bound_squared, `scale` bounds every |coordinate| of the points
/// and of the mesh): emit(local, sample) for each point within the bound (its signed distance
/// to the double search's triangle, the pseudonormal sign), emit_outside(local,
/// kBandSideNone) for each other, `local` the block-local index x + 8 y + 64 z. Returns the
/// points beyond.
template <typename EmitFn, typename OutsideFn>
int64_t sweep_block(const PreparedMesh& mesh, const TriangleBvh& bvh, const Lattice& lattice, const GridBlock& block,
                    double bound_squared, double scale, SweepScratch& scratch, EmitFn emit, OutsideFn emit_outside) {
    const BvhView<double> view = bvh.view<double>();
    const double hh = lattice.half_spacing(), reach = std::sqrt(bound_squared);
    BandSweepBlock points;
    points.points = block.resolution;
    // Covers the rounding of the triangles' boxes and of Q_d near the bound (band_sweep.h).
    points.margin = hh + 1e-5 * reach + 0x1p-40 * scale;
    points.rounding = 0x1p-44 * scale;
    for (int k = 0; k < kBandBlockDim; ++k) {  // Lattice::position_of_coords, axis by axis
        points.x[k] = lattice.origin.x + hh * double(block.first.x + block.step * k);
        points.y[k] = lattice.origin.y + hh * double(block.first.y + block.step * k);
        points.z[k] = lattice.origin.z + hh * double(block.first.z + block.step * k);
    }
    const Int3 r = block.resolution;
    const double m = reach + points.margin;
    const Vec3d lo(points.x[0] - m, points.y[0] - m, points.z[0] - m);
    const Vec3d hi(points.x[r.x - 1] + m, points.y[r.y - 1] + m, points.z[r.z - 1] + m);
    scratch.slots.clear();
    for_each_leaf_meeting_box(view.nodes, lo, hi, [&](int32_t first, int32_t count) {
        for (int32_t s = first; s < first + count; ++s) scratch.slots.push_back(s);
    });
    // Nearest first (by vertex B from the block's centre): the rows' bests shrink soonest, and
    // the sweep skips more of the triangles after.
    const Vec3d centre = (lo + hi) * 0.5;
    scratch.order.clear();
    for (int32_t s : scratch.slots) {
        const PackedTriangle<double>& t = view.packed[s];
        scratch.order.push_back({length_squared(Vec3d(t.bx, t.by, t.bz) - centre), s});
    }
    std::sort(scratch.order.begin(), scratch.order.end());
    for (size_t i = 0; i < scratch.order.size(); ++i) scratch.slots[i] = scratch.order[i].second;
    for (int i = 0; i < kBandBlockPoints; ++i) {  // padding: never won
        const bool real = i % kBandBlockDim < r.x && (i / kBandBlockDim) % kBandBlockDim < r.y && i / (kBandBlockDim * kBandBlockDim) < r.z;
        scratch.best_q[i] = real ? bound_squared : -1.0;
        scratch.best_triangle[i] = -1;
    }
    active_cpu_kernels().sweep_band_block(view.packed, view.triangle_index, scratch.slots.data(), int(scratch.slots.size()),
                                          points, bound_squared, scratch.best_q, scratch.best_triangle);
    const MeshView<double> exact = mesh.buffers<double>().view();
    int64_t beyond = 0;
    for (int z = 0; z < r.z; ++z)
        for (int y = 0; y < r.y; ++y)
            for (int x = 0; x < r.x; ++x) {
                const int local = x + kBandBlockDim * (y + kBandBlockDim * z);
                const int32_t t = scratch.best_triangle[local];
                if (t < 0) {
                    emit_outside(local, kBandSideNone);
                    ++beyond;
                    continue;
                }
                emit(local, signed_distance_to_triangle(exact, Vec3d(points.x[x], points.y[y], points.z[z]), t));
            }
    return beyond;
}

}  // namespace sdf::cpu_bvh
