/// @file band_sweep.h
/// @brief The triangle sweep of a solid's sparse band, written once for host and device: the
/// triangles visit the band's points near them, and each point keeps the least Q_d within a
/// bound (squared_distance() on PackedTriangle<double> at the point, the quantity the double
/// search and the float search's certificate rank by), ties to the smaller triangle index (the
/// tie rule of every search, wins_tie): the double search's triangle, whatever the tree, of
/// every point within the band, and none where no triangle lies within the bound (such a point
/// lies beyond the band and takes its side from its neighbours, band_sides.h).
///
/// The CUDA sweep (cuda/bvh/bvh_band_blocks.cu) walks each triangle's slab over the blocks; the
/// CPU's (sweep_band_block) walks each block's triangles, found by a box query of the BVH, row
/// by row, a row's 8 points one vector.
#pragma once

#include <cmath>
#include <cstdint>

#include "kernels/distance/packed_triangle.h"
#include "kernels/lattice/band_blocks.h"

namespace sdf {

/// The sweep's bound on Q_d for a band of half width `width`: W with a relative margin of 1e-6
/// and an absolute one of 2^-30 of the coordinates' scale (`scale` bounds every |coordinate|
/// of the points and of the mesh), far above Q_d's rounding in distance terms (about
/// u (|B - P| scale + 8 extent^2) / W, |B - P| <= the mesh's extent <= 16384 W), so that every
/// point the finalize finds within W has its triangle. No sliver reach: Q_d ranks slivers
/// exactly as the double search does (the float search ranks them by their edges).
inline double band_sweep_bound_squared(double width, double scale) {
    const double r = (width + 0x1p-30 * scale) * (1.0 + 1e-6);
    return r * r;
}

/// A triangle's box dilated by `reach`, from its vertices B, B + E0, B + E1 (packed as 2 E0,
/// 2 E1; the callers' margins cover the rounding).
SDF_CPU_GPU SDF_INLINE void dilated_box(const PackedTriangle<double>& t, double reach, Vec3d& lo, Vec3d& hi) {
    const Vec3d b(t.bx, t.by, t.bz), v1(t.bx + 0.5 * t.e0x, t.by + 0.5 * t.e0y, t.bz + 0.5 * t.e0z),
        v2(t.bx + 0.5 * t.e1x, t.by + 0.5 * t.e1y, t.bz + 0.5 * t.e1z);
    // Selects, not fmin/fmax (calls on x86; the vertices are finite).
    const auto lower = [](double a, double b) { return a < b ? a : b; };
    const auto upper = [](double a, double b) { return a > b ? a : b; };
    lo = Vec3d(lower(b.x, lower(v1.x, v2.x)) - reach, lower(b.y, lower(v1.y, v2.y)) - reach, lower(b.z, lower(v1.z, v2.z)) - reach);
    hi = Vec3d(upper(b.x, upper(v1.x, v2.x)) + reach, upper(b.y, upper(v1.y, v2.y)) + reach, upper(b.z, upper(v1.z, v2.z)) + reach);
}

/// Whether point x lies beyond the bound from the triangle by its plane alone, before Q_d is
/// evaluated: the distance h from the plane is a lower bound of the distance, and what the
/// doubles lose stays below 2^-40 |B - x|^2 (h's, through the unit normal's direction: about
/// 200 u off for a triangle that is not a sliver, a few u for a sliver's accurate normal; Q_d's,
/// about 2^-47 |B - x|^2), so a point culled here has Q_d above the bound too. A normal of
/// zero (h = 0) or NaN culls nothing.
SDF_CPU_GPU SDF_INLINE bool beyond_plane(const PackedTriangle<double>& t, const Vec3d& x, double bound_squared) {
    const double dx = t.bx - x.x, dy = t.by - x.y, dz = t.bz - x.z;
    const double h = t.nx * dx + t.ny * dy + t.nz * dz, f = dx * dx + dy * dy + dz * dz;
    return h * h > 1.01 * bound_squared + 0x1p-40 * f;
}

/// A half width R of the triangle's slab over a box of diagonal `span` around it: beyond_plane
/// culls every point of the box with |h| > R (R^2 bounds its threshold there, f <= 4 |span|^2).
SDF_CPU_GPU SDF_INLINE double sweep_slab_half_width(double bound_squared, const Vec3d& span) {
    return sqrt(1.01 * bound_squared + 0x1p-40 * length_squared(span) * 4);
}

/// One block's points for the CPU sweep: their positions axis by axis (a lattice's position is
/// separable: lattice.position_of_coords), the real points per axis (a block at the coset's
/// end is cut), and the margin that the box tests add (the rounding of the boxes).
struct BandSweepBlock {
    double x[kBandBlockDim], y[kBandBlockDim], z[kBandBlockDim];
    Int3 points{};
    double margin = 0;    ///< of the dilated boxes (points_within)
    double rounding = 0;  ///< of the triangles' boxes, computed from their packed vertices
};

/// Points [first, last] of an axis's ascending positions `p[0..n)` within [lo - margin,
/// hi + margin]; first > last where none.
SDF_CPU_GPU SDF_INLINE void points_within(const double* p, int n, double lo, double hi, double margin, int& first, int& last) {
    first = 0;
    last = n - 1;
    while (first < n && !(p[first] >= lo - margin)) ++first;
    while (last >= first && !(p[last] <= hi + margin)) --last;
}

namespace detail {

/// One row of a block (8 points along x, `x`, at y and z) against one triangle: each point's
/// best (Q_d, triangle) replaced where the triangle wins (smaller Q_d, or equal and the smaller
/// index; a point without one yet, triangle -1, keeps the bound as its Q_d). Vectorised over
/// the row (-ffp-contract=off everywhere: the vector's Q_d is the scalar search's, bit for bit).
template <bool kSliver>
SDF_INLINE double sweep_row(const PackedTriangle<double>& t, int32_t triangle, const double* x, double y, double z,
                            double* __restrict best_q, int32_t* __restrict best_triangle) {
    double worst = -1;  // returned from the registers (a reload of the row would wait on its stores)
#pragma omp simd reduction(max : worst)
    for (int k = 0; k < kBandBlockDim; ++k) {
        const double q = kSliver ? sliver_squared_distance(t, x[k], y, z) : branch_free_squared_distance(t, x[k], y, z);
        const bool wins = (q < best_q[k]) | ((q == best_q[k]) & ((best_triangle[k] < 0) | (triangle < best_triangle[k])));  // no branches
        const double best = wins ? q : best_q[k];
        best_q[k] = best;
        best_triangle[k] = wins ? triangle : best_triangle[k];
        worst = best > worst ? best : worst;
    }
    return worst;
}

/// The largest of a row's bests (at least -1, the padding's).
SDF_INLINE double largest_of_row(const double* q) {
    double w = -1;
#pragma omp simd reduction(max : w)
    for (int k = 0; k < kBandBlockDim; ++k) w = q[k] > w ? q[k] : w;
    return w;
}

/// max(0, lo - x, x - hi): how far x lies outside [lo, hi] (written out: std::fmax is a call on x86).
SDF_INLINE double outside_interval(double x, double lo, double hi) {
    const double below = lo - x, above = x - hi;
    return below > 0 ? below : above > 0 ? above : 0.0;
}

}  // namespace detail

/// The CPU sweep of one block: each of the `count` candidate triangles (BVH slots `slots`:
/// every triangle whose box, dilated by the bound's root, may meet the block's; nearest first
/// is fastest) against the rows of the block that it may still win. `best_q` and
/// `best_triangle` (kBandBlockPoints each, block-local index x + 8 y + 64 z) come filled with
/// the bound and -1 at the block's points, and with -1 and -1 at its padding (never won); a
/// point left at -1 has no triangle within the bound. A row is skipped where every point of it
/// that the triangle's dilated box holds lies farther from the triangle's box, or beyond its
/// plane on one side (h is linear along the row), than the row's worst best so far allows:
/// beyond_plane's margins, with that worst best as the bound, so that a skipped point's Q_d
/// exceeds its best. Work grows with the triangles' points near them, not with a search per
/// point.
inline void sweep_band_block(const PackedTriangle<double>* packed, const int32_t* triangle_index, const int32_t* slots,
                             int count, const BandSweepBlock& block, double bound_squared, double* best_q,
                             int32_t* best_triangle) {
    constexpr int kRows = kBandBlockDim * kBandBlockDim;
    double worst[kRows];  // each row's largest best_q (its padding: -1)
    for (int r = 0; r < kRows; ++r) worst[r] = detail::largest_of_row(best_q + kBandBlockDim * r);
    const double reach = std::sqrt(bound_squared);
    for (int c = 0; c < count; ++c) {
        const PackedTriangle<double> t = packed[slots[c]];  // a local copy: the rows' stores cannot alias it
        const int32_t triangle = triangle_index[slots[c]];
        Vec3d lo, hi;  // the triangle's box
        dilated_box(t, 0.0, lo, hi);
        int x0, x1, y0, y1, z0, z1;
        points_within(block.x, block.points.x, lo.x - reach, hi.x + reach, block.margin, x0, x1);
        points_within(block.y, block.points.y, lo.y - reach, hi.y + reach, block.margin, y0, y1);
        points_within(block.z, block.points.z, lo.z - reach, hi.z + reach, block.margin, z0, z1);
        if (x0 > x1 || y0 > y1 || z0 > z1) continue;
        // The rounding allowance of beyond_plane: f <= 4 |span|^2 over the dilated box.
        const Vec3d span = (hi - lo) + Vec3d(2 * reach);
        const double allowance = 0x1p-40 * length_squared(span) * 4;
        lo = lo - Vec3d(block.rounding);
        hi = hi + Vec3d(block.rounding);
        const double bx = lo.x > block.x[x1] ? lo.x - block.x[x1] : block.x[x0] > hi.x ? block.x[x0] - hi.x : 0.0;  // [x0, x1]'s
        const bool sliver = is_interior_sliver(t);
        for (int z = z0; z <= z1; ++z) {
            const double bz = detail::outside_interval(block.z[z], lo.z, hi.z);
            for (int y = y0; y <= y1; ++y) {
                const int r = y + kBandBlockDim * z;
                // A Q_d may round below 0 on the surface: 1% of |worst| above worst, either sign.
                const double threshold = worst[r] + 0.01 * std::abs(worst[r]) + allowance;
                const double by = detail::outside_interval(block.y[y], lo.y, hi.y);
                if (bx * bx + by * by + bz * bz > threshold) continue;  // the box
                const double hyz = t.ny * (t.by - block.y[y]) + t.nz * (t.bz - block.z[z]);
                const double h0 = t.nx * (t.bx - block.x[x0]) + hyz, h1 = t.nx * (t.bx - block.x[x1]) + hyz;
                if (((h0 > 0) == (h1 > 0)) && h0 * h0 > threshold && h1 * h1 > threshold) continue;  // the plane
                double* q = best_q + kBandBlockDim * r;
                int32_t* b = best_triangle + kBandBlockDim * r;
                worst[r] = sliver ? detail::sweep_row<true>(t, triangle, block.x, block.y[y], block.z[z], q, b)
                                  : detail::sweep_row<false>(t, triangle, block.x, block.y[y], block.z[z], q, b);
            }
        }
    }
}

}  // namespace sdf
