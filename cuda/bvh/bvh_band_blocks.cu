// The CUDA BVH sampler's sparse narrow band (issue 35): the active blocks of 8^3 points
// (core/sampling/sparse_band.h) sampled in device memory. Their sorted ids go up once; each
// batch of blocks (as many as 80% of free device memory holds) runs the dense lattice path's
// kernels on them: the warp or candidates search with the band's brick skip (a warp's brick
// is 8 x 4 x 4 points of one block, as a lattice slab's), the certificate, and the same
// finalize_samples() with the band's width, written straight into block-major arrays; then
// one copy per channel the band holds into its host arrays (written there for the first
// time: the sampler allocates them without a fill). Padding (points of a block beyond the
// coset's resolution) is marked "outside, positive side" before the search, so finalize
// writes it +W, gradient 0, kOutsideBandTriangle: the host's values for padding.
// On a solid (the pseudonormal sign, W >= one spacing) no point is searched: each triangle
// sweeps the points near it (sweep_band_triangles: the double search's triangle of every point
// within W, exactly); a point beyond finds no triangle and takes its side from its neighbours
// (flood_band_sides), a block of such points from its point 0's nearest triangle
// (sweep_block_origins). Every other band runs the search.
#include <algorithm>
#include <climits>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/sampling/certified_search.h"
#include "core/sampling/search_range.h"
#include "core/sampling/sparse_band.h"
#include "cuda/bvh/bvh_bound_sampler.cuh"
#include "cuda/bvh/bvh_candidates_kernel.cuh"
#include "cuda/bvh/bvh_warp_kernel.cuh"
#include "cuda/util/cuda_check.h"
#include "cuda/util/cuda_device.h"
#include "cuda/util/device_guard.h"
#include "kernels/lattice/band_blocks.h"
#include "kernels/lattice/band_sides.h"

namespace sdf::cuda {
namespace {

/// A batch of active blocks as a piece (cuda/sampling/point_pieces.h): piece-local id i is point
/// i % 512 (block-local, x fastest) of block ids[i / 512], and its result goes to slot i of
/// the batch's block-major arrays, padding included (never discarded).
struct BandBlocksPiece {
    Lattice lattice;
    BandBlockGrid grid;
    const int64_t* ids = nullptr;  ///< the batch's block ids, on the device
    int64_t blocks = 0;

    SDF_CPU_GPU int64_t size() const { return blocks * kBandBlockPoints; }
    SDF_CPU_GPU int64_t block_local(int64_t i) const { return i; }
    SDF_CPU_GPU Vec3d position(int64_t i) const {
        const BandBlockCoords b = grid.block_coords(ids[i / kBandBlockPoints]);
        return lattice.position_of_coords(grid.point_coords(b, int(i % kBandBlockPoints)));
    }
    SDF_CPU_GPU int64_t output_index(int64_t i) const { return i; }
};

/// The warp kernels' layout over the blocks (bvh_warp_kernel.cuh's SlabLayout for a band):
/// 128 threads per block, each a run of kRunPoints consecutive points along x; the 4 warps
/// of a block are its bricks of 8 x 4 x 4 points (lane: 2 runs x 4 rows x 4 layers).
struct BandBlocksLayout {
    static constexpr int kPoints = kRunPoints;
    static constexpr int kThreadsPerBlock = kBandBlockPoints / kRunPoints;
    static_assert(kBandBlockDim == 2 * kRunPoints && kThreadsPerBlock == 4 * 32, "a block is 4 warps of 8 x 4 x 4 points");
    BandBlocksPiece piece;

    SDF_CPU_GPU int64_t threads() const { return piece.blocks * kThreadsPerBlock; }
    SDF_CPU_GPU int points_of(int64_t t, int64_t& first) const {
        first = 0;
        if (t >= threads()) return 0;
        const int64_t a = t / kThreadsPerBlock;
        const int u = int(t % kThreadsPerBlock), w = u / 32, lane = u % 32;
        const int x = (lane & 1) * kRunPoints, y = (w & 1) * 4 + ((lane >> 1) & 3), z = (w >> 1) * 4 + (lane >> 3);
        const BandBlockCoords b = piece.grid.block_coords(piece.ids[a]);
        const Int3 n = piece.grid.coset[b.coset].points;
        const Int3 p{b.block.x * kBandBlockDim + x, b.block.y * kBandBlockDim + y, b.block.z * kBandBlockDim + z};
        if (p.x >= n.x || p.y >= n.y || p.z >= n.z) return 0;  // padding: never searched
        first = a * kBandBlockPoints + x + kBandBlockDim * (y + kBandBlockDim * z);
        return min(kRunPoints, n.x - p.x);
    }
    SDF_CPU_GPU Vec3d position(int64_t i) const { return piece.position(i); }
};

__global__ void fill_nearest(int* nearest, int64_t n, int code) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < n) nearest[i] = code;
}

/// Prepared-mesh triangle indices to the mesh file's face order, in place.
__global__ void to_source_order(int* triangle, int64_t n, const int32_t* source_triangle) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const int t = triangle[i];
    if (t >= 0) triangle[i] = source_triangle[t];
}

/// The sides of the points a bounded search left without a triangle (kOutsideBandFlood): one
/// CUDA block of 512 threads per band block, each point taking a neighbour's side
/// (kernels/lattice/band_sides.h) until none changes. A block of such points only takes the
/// side of its point 0, at its nearest triangle in double (that point too lies beyond the
/// band): `block_nearest`'s (the sweep's, sweep_block_origins) where it found one, else every
/// triangle's. counters: points flooded, blocks signed by a search,
/// points left without a side (never: the host checks).
template <typename T>
__global__ void __launch_bounds__(kBandBlockPoints)
    flood_band_sides(BvhView<T> bvh, MeshView<double> mesh, BandBlocksPiece piece, const int* nearest, const int* block_nearest,
                     double width, double* distance, unsigned long long* counters) {
    __shared__ volatile signed char side[kBandBlockPoints];
    const int local = threadIdx.x;
    const int64_t i = int64_t(blockIdx.x) * kBandBlockPoints + local;
    const BandBlockCoords b = piece.grid.block_coords(piece.ids[blockIdx.x]);
    const bool padding = piece.grid.padding(b, local);
    const bool flood = !padding && nearest[i] == kOutsideBandFlood;
    side[local] = padding ? kBandSidePadding : flood ? kBandSideNone : signbit(distance[i]) ? kBandSideInside : kBandSideOutside;
    const int flooded = __syncthreads_count(flood);
    if (flooded == 0) return;  // uniform over the block
    if (!__syncthreads_or(!flood && !padding)) {
        // Point 0's side (a block's point 0 is never padding) at its nearest triangle in
        // double: the sweep's, else over every triangle, the block's threads sharing them
        // (ties: the smaller index, as closest_triangle_bvh.h's rule): exact where a float
        // search may tie across a thin part.
        __shared__ double nearest_d[kBandBlockPoints];
        __shared__ int nearest_t[kBandBlockPoints];
        const Vec3d p = piece.position(int64_t(blockIdx.x) * kBandBlockPoints);
        const int swept = block_nearest ? block_nearest[blockIdx.x] : -1;
        if (swept >= 0 && swept != INT_MAX) {  // uniform over the block
            if (local == 0) {
                side[0] = signed_distance_to_triangle(mesh, p, swept).distance < 0 ? kBandSideInside : kBandSideOutside;
                atomicAdd(counters + 1, 1ull);
            }
            __syncthreads();
        } else {
            double best = INFINITY;
            int best_t = -1;
            for (int t = local; t < mesh.num_triangles; t += kBandBlockPoints) {
                const double d = fabs(signed_distance_to_triangle(mesh, p, t).distance);
                if (d < best) {
                    best = d;
                    best_t = t;
                }
            }
            nearest_d[local] = best;
            nearest_t[local] = best_t;
            __syncthreads();
            for (int half = kBandBlockPoints / 2; half > 0; half /= 2) {
                if (local < half) {
                    const double d = nearest_d[local + half];
                    const int t = nearest_t[local + half];
                    if (t >= 0 && (d < nearest_d[local] || (d == nearest_d[local] && (nearest_t[local] < 0 || t < nearest_t[local])))) {
                        nearest_d[local] = d;
                        nearest_t[local] = t;
                    }
                }
                __syncthreads();
            }
            if (local == 0) {
                side[0] = signed_distance_to_triangle(mesh, p, nearest_t[0]).distance < 0 ? kBandSideInside : kBandSideOutside;
                atomicAdd(counters + 1, 1ull);
                atomicAdd(counters + 3, 1ull);
            }
            __syncthreads();
        }
    }
    const auto side_of = [&](int j) { return static_cast<signed char>(side[j]); };
    for (;;) {
        bool changed = false;
        if (side[local] == kBandSideNone) {
            const signed char s = neighbour_side(side_of, local);
            if (s != kBandSideNone) {
                side[local] = s;
                changed = true;
            }
        }
        if (!__syncthreads_or(changed)) break;
    }
    if (flood) distance[i] = side[local] == kBandSideInside ? -width : width;
    if (local == 0) atomicAdd(counters + 0, (unsigned long long)flooded);
    if (flood && side[local] == kBandSideNone) atomicAdd(counters + 2, 1ull);
}

/// The band's points of a batch's blocks as their masks (SparseBandField::band_mask): bit
/// `local` of a block set where its point's triangle is not kOutsideBandTriangle (padding's
/// is). One thread per point, one ballot per warp: the warp's 32 points are 32-bit half
/// i / 32 of the masks' 64-bit words (little-endian, as the host reads them). n is a whole
/// number of blocks, so a warp is wholly in or out.
__global__ void mark_band_points(const int* triangle, int64_t n, uint32_t* mask) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i - (threadIdx.x & 31) >= n) return;
    const unsigned bits = __ballot_sync(0xffffffffu, i < n && triangle[i] != kOutsideBandTriangle);
    if ((threadIdx.x & 31) == 0) mask[i >> 5] = bits;
}

/// The triangle sweep (a solid's bounded band, in place of the bounded search): each
/// triangle visits the lattice points of its box dilated by the bound, and each point keeps the
/// least Q_d (squared_distance() on PackedTriangle<double> at the point, the quantity the
/// double search and the float search's certificate rank by) within the bound, ties to the
/// smaller triangle index (wins_tie): the double search's triangle, whatever the tree, and
/// none (kOutsideBandFlood, the flood's) where no triangle is within the bound. Two passes: the
/// least Q_d as an ordered 64-bit key (atomicMin), then the least triangle index among the
/// triangles at that key. Work grows with the band's points near each triangle, not with a
/// search per point of every active block (3-6 times the band's points).
constexpr int kSweepThreads = 128;
/// Blocks of a triangle's box whose batch indices are kept in shared memory; a larger box
/// (a triangle many blocks wide) looks each point's block up in the sorted ids instead.
constexpr int kSweepCachedBlocks = 2048;
constexpr unsigned long long kSweepNone = ~0ull;

/// A double's order as an unsigned key (negative values below positive ones).
__device__ SDF_INLINE unsigned long long ordered_key(double q) {
    const unsigned long long bits = static_cast<unsigned long long>(__double_as_longlong(q));
    return (bits >> 63) ? ~bits : bits | (1ull << 63);
}

/// Index of block `id` among the batch's sorted ids, or -1.
__device__ int64_t batch_index(const BandBlocksPiece& piece, int64_t id) {
    int64_t lo = 0, hi = piece.blocks;
    while (lo < hi) {
        const int64_t mid = lo + (hi - lo) / 2;
        if (piece.ids[mid] < id) lo = mid + 1;
        else hi = mid;
    }
    return lo < piece.blocks && piece.ids[lo] == id ? lo : -1;
}

/// The coset points [p0, p1] (per axis, clamped to the coset) whose positions may lie in
/// [lo, hi]: one point of margin covers the rounding of the box and of the positions.
__device__ SDF_INLINE bool coset_range(const Lattice& lattice, const BandCoset& coset, const Vec3d& lo, const Vec3d& hi, Int3& p0,
                                    Int3& p1) {
    const double hh = lattice.half_spacing();
    for (int k = 0; k < 3; ++k) {
        // Point p of the coset lies at origin + hh (first + 2 p).
        const double a = floor(((lo[k] - lattice.origin[k]) / hh - coset.first[k]) / 2) - 1;
        const double b = ceil(((hi[k] - lattice.origin[k]) / hh - coset.first[k]) / 2) + 1;
        if (!(a <= double(coset.points[k] - 1)) || !(b >= 0)) return false;  // NaN too
        p0[k] = a < 0 ? 0 : int(a);
        p1[k] = b > double(coset.points[k] - 1) ? coset.points[k] - 1 : int(b);
    }
    return true;
}

template <int kPass>
__global__ void __launch_bounds__(kSweepThreads)
    sweep_band_triangles(const PackedTriangle<double>* packed, const int32_t* triangle_index, int triangles,
                         BandBlocksPiece piece, double bound_squared, unsigned long long* best_key, int* best_triangle) {
    __shared__ int64_t cached[kSweepCachedBlocks];
    const double reach = sqrt(bound_squared);
    for (int s = blockIdx.x; s < triangles; s += gridDim.x) {
        const PackedTriangle<double> t = packed[s];
        const int triangle = triangle_index[s];
        // Its vertices B, B + E0, B + E1 (packed as 2 E0, 2 E1; the index margin covers the rounding).
        const Vec3d b(t.bx, t.by, t.bz), v1(t.bx + 0.5 * t.e0x, t.by + 0.5 * t.e0y, t.bz + 0.5 * t.e0z),
            v2(t.bx + 0.5 * t.e1x, t.by + 0.5 * t.e1y, t.bz + 0.5 * t.e1z);
        const Vec3d lo(fmin(b.x, fmin(v1.x, v2.x)) - reach, fmin(b.y, fmin(v1.y, v2.y)) - reach, fmin(b.z, fmin(v1.z, v2.z)) - reach);
        const Vec3d hi(fmax(b.x, fmax(v1.x, v2.x)) + reach, fmax(b.y, fmax(v1.y, v2.y)) + reach, fmax(b.z, fmax(v1.z, v2.z)) + reach);
        for (int c = 0; c < piece.grid.cosets; ++c) {
            const BandCoset& coset = piece.grid.coset[c];
            Int3 p0, p1;
            if (!coset_range(piece.lattice, coset, lo, hi, p0, p1)) continue;  // uniform over the CUDA block
            const Int3 b0{p0.x >> kBandBlockLog2, p0.y >> kBandBlockLog2, p0.z >> kBandBlockLog2};
            const Int3 nb{(p1.x >> kBandBlockLog2) - b0.x + 1, (p1.y >> kBandBlockLog2) - b0.y + 1, (p1.z >> kBandBlockLog2) - b0.z + 1};
            const int64_t box_blocks = int64_t(nb.x) * nb.y * nb.z;
            const bool use_cache = box_blocks <= kSweepCachedBlocks;
            if (use_cache) {
                for (int j = threadIdx.x; j < box_blocks; j += blockDim.x)
                    cached[j] = batch_index(piece, piece.grid.block_id(c, {b0.x + j % nb.x, b0.y + (j / nb.x) % nb.y, b0.z + j / (nb.x * nb.y)}));
                __syncthreads();
            }
            const Int3 np{p1.x - p0.x + 1, p1.y - p0.y + 1, p1.z - p0.z + 1};
            const int64_t points = int64_t(np.x) * np.y * np.z;
            const bool narrow = points < (int64_t(1) << 32);  // 32-bit divisions (a 64-bit one is ~4x dearer)
            for (int64_t j = threadIdx.x; j < points; j += blockDim.x) {
                Int3 p;
                if (narrow) {
                    const uint32_t u = uint32_t(j), row = u / uint32_t(np.x);
                    p = {p0.x + int(u - row * uint32_t(np.x)), p0.y + int(row % uint32_t(np.y)), p0.z + int(row / uint32_t(np.y))};
                } else {
                    const int64_t row = j / np.x;
                    p = {p0.x + int(j - row * np.x), p0.y + int(row % np.y), p0.z + int(row / np.y)};
                }
                const Int3 pb{p.x >> kBandBlockLog2, p.y >> kBandBlockLog2, p.z >> kBandBlockLog2};
                const int64_t a = use_cache ? cached[(pb.x - b0.x) + int64_t(nb.x) * ((pb.y - b0.y) + int64_t(nb.y) * (pb.z - b0.z))]
                                            : batch_index(piece, piece.grid.block_id(c, pb));
                if (a < 0) continue;  // not an active block of this batch
                const Vec3d x = piece.lattice.position_of_coords({coset.first.x + 2 * p.x, coset.first.y + 2 * p.y, coset.first.z + 2 * p.z});
                // Beyond twice the reach from the triangle's plane: beyond the bound, whatever
                // Q_d's rounding (about 2^-50 |B - P|^2, small against 3 bounds while |B - P|
                // stays below 2^20 reaches; farther points are not culled).
                const double dx = t.bx - x.x, dy = t.by - x.y, dz = t.bz - x.z;
                const double h = t.nx * dx + t.ny * dy + t.nz * dz, f = dx * dx + dy * dy + dz * dz;
                if (h * h > 4 * bound_squared && f < 0x1p40 * bound_squared) continue;
                double q = squared_distance(t, x.x, x.y, x.z);
                if (!(q <= bound_squared)) continue;
                if (q == 0) q = 0;  // -0 ties +0, as the search's comparison
                const int64_t i = a * kBandBlockPoints + (p.x & (kBandBlockDim - 1)) +
                                  kBandBlockDim * ((p.y & (kBandBlockDim - 1)) + kBandBlockDim * (p.z & (kBandBlockDim - 1)));
                const unsigned long long key = ordered_key(q);
                if constexpr (kPass == 0) {
                    if (key < best_key[i]) atomicMin(best_key + i, key);  // a stale read only costs an atomic
                } else if (key == best_key[i]) {
                    atomicMin(best_triangle + i, triangle);
                }
            }
            if (use_cache) __syncthreads();  // before the next box overwrites the cache
        }
    }
}

/// Blocks whose every lattice point the sweep left without a triangle (their sides all from
/// the flood): block_nearest INT_MAX (to be found), else -1.
__global__ void __launch_bounds__(kBandBlockPoints) find_unsigned_blocks(const int* nearest, int* block_nearest) {
    const bool any = __syncthreads_or(nearest[int64_t(blockIdx.x) * kBandBlockPoints + threadIdx.x] >= 0);
    if (threadIdx.x == 0) block_nearest[blockIdx.x] = any ? -1 : INT_MAX;
}

/// The nearest triangle in double of point 0 of each such block (flood_band_sides' side for
/// the block), by the same sweep within a wider bound (W and the block's extent): each
/// triangle visits the block origins near it. Q_d and the tie rule as sweep_band_triangles.
template <int kPass>
__global__ void __launch_bounds__(kSweepThreads)
    sweep_block_origins(const PackedTriangle<double>* packed, const int32_t* triangle_index, int triangles,
                        BandBlocksPiece piece, double bound_squared, unsigned long long* best_key, int* block_nearest) {
    const double reach = sqrt(bound_squared);
    for (int s = blockIdx.x; s < triangles; s += gridDim.x) {
        const PackedTriangle<double> t = packed[s];
        const int triangle = triangle_index[s];
        const Vec3d b(t.bx, t.by, t.bz), v1(t.bx + 0.5 * t.e0x, t.by + 0.5 * t.e0y, t.bz + 0.5 * t.e0z),
            v2(t.bx + 0.5 * t.e1x, t.by + 0.5 * t.e1y, t.bz + 0.5 * t.e1z);
        const Vec3d lo(fmin(b.x, fmin(v1.x, v2.x)) - reach, fmin(b.y, fmin(v1.y, v2.y)) - reach, fmin(b.z, fmin(v1.z, v2.z)) - reach);
        const Vec3d hi(fmax(b.x, fmax(v1.x, v2.x)) + reach, fmax(b.y, fmax(v1.y, v2.y)) + reach, fmax(b.z, fmax(v1.z, v2.z)) + reach);
        for (int c = 0; c < piece.grid.cosets; ++c) {
            const BandCoset& coset = piece.grid.coset[c];
            Int3 p0, p1;
            if (!coset_range(piece.lattice, coset, lo, hi, p0, p1)) continue;
            // The blocks whose point 0 (8 b) lies in [p0, p1].
            const Int3 b0{(p0.x + kBandBlockDim - 1) >> kBandBlockLog2, (p0.y + kBandBlockDim - 1) >> kBandBlockLog2,
                          (p0.z + kBandBlockDim - 1) >> kBandBlockLog2};
            const Int3 nb{(p1.x >> kBandBlockLog2) - b0.x + 1, (p1.y >> kBandBlockLog2) - b0.y + 1, (p1.z >> kBandBlockLog2) - b0.z + 1};
            if (nb.x <= 0 || nb.y <= 0 || nb.z <= 0) continue;
            const int64_t count = int64_t(nb.x) * nb.y * nb.z;
            for (int64_t j = threadIdx.x; j < count; j += blockDim.x) {
                const int64_t row = j / nb.x;
                const Int3 pb{b0.x + int(j - row * nb.x), b0.y + int(row % nb.y), b0.z + int(row / nb.y)};
                const int64_t a = batch_index(piece, piece.grid.block_id(c, pb));
                if (a < 0 || block_nearest[a] < 0) continue;  // inactive, or signed by its own points
                const Vec3d x = piece.lattice.position_of_coords(
                    {coset.first.x + 2 * kBandBlockDim * pb.x, coset.first.y + 2 * kBandBlockDim * pb.y, coset.first.z + 2 * kBandBlockDim * pb.z});
                double q = squared_distance(t, x.x, x.y, x.z);
                if (!(q <= bound_squared)) continue;
                if (q == 0) q = 0;
                const unsigned long long key = ordered_key(q);
                if constexpr (kPass == 0) {
                    if (key < best_key[a]) atomicMin(best_key + a, key);
                } else if (key == best_key[a]) {
                    atomicMin(block_nearest + a, triangle);
                }
            }
        }
    }
}

/// Points the sweep left without a triangle: kOutsideBandFlood (their side from the flood),
/// padding kOutsideBandOutside (as the search leaves it: +W).
__global__ void finish_sweep(BandBlocksPiece piece, const unsigned long long* best_key, int* nearest) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= piece.size() || best_key[i] != kSweepNone) return;
    const bool padding = piece.grid.padding(piece.grid.block_coords(piece.ids[i / kBandBlockPoints]), int(i % kBandBlockPoints));
    nearest[i] = padding ? kOutsideBandOutside : kOutsideBandFlood;
}

/// Distances rounded to float32 (float(d), as the band's host type rounds them) for a band
/// held in float32: half the download and half the host's memory.
__global__ void round_to_float32(const double* distance, int64_t n, float* out) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < n) out[i] = float(distance[i]);
}

size_t device_bytes_in_use() {
    size_t free_bytes = 0, total = 0;
    CUDA_CHECK(cudaMemGetInfo(&free_bytes, &total));
    return total - free_bytes;
}

}  // namespace

BandBlockKernel BoundCudaBvh::band_block_kernel(double width) const {
    // The kernels whose layout is a warp's brick; the others answer the band's point lists.
    if (kernel_ != BvhGpuKernel::Warp && kernel_ != BvhGpuKernel::Candidates) return {};
    return [this, width](SparseBandField& band, size_t first, size_t last) {
        const std::lock_guard<std::mutex> lock(mutex_);
        const DeviceGuard on_device(options_.device);
        with_precision(options_.precision, [&](auto zero) { band_blocks_as<decltype(zero)>(band, first, last, width); });
    };
}

template <typename T>
void BoundCudaBvh::band_blocks_as(SparseBandField& band, size_t first, size_t last, double width) const {
    const DeviceBvh<T>& dev = tree<T>();
    const Lattice& lattice = band.lattice;
    require_search_range(mesh(), lattice, options_.precision);
    const int64_t blocks = int64_t(last - first);
    EventTimer upload, compute, download;
    EventTimer search_stage, finalize_stage, flood_stage;  // compute's parts
    DeviceBuffer<int64_t> ids{size_t(blocks)};
    upload.begin();
    ids.upload(band.active.data() + first, size_t(blocks));
    upload.end();

    // Blocks per batch: 80% of free device memory (max_points_per_piece caps it, as a slab's pieces).
    const size_t free_bytes = free_device_memory();
    const bool float32 = band.distance.float32();  // the download rounds them on the device
    const int64_t block_bytes = int64_t(PieceResults::bytes_per_point() + (float32 ? sizeof(float) : 0)) * kBandBlockPoints;
    int64_t batch = int64_t(0.8 * double(free_bytes)) / block_bytes;
    if (batch < 1 && options_.max_points_per_piece <= 0)
        throw std::runtime_error("CUDA BVH sampler: " + std::to_string(free_bytes >> 20) +
                                 " MiB of free GPU memory cannot hold one block of the sparse band (" +
                                 std::to_string(block_bytes) + " bytes)");
    if (options_.max_points_per_piece > 0) batch = std::min(batch, options_.max_points_per_piece / kBandBlockPoints);
    batch = std::clamp<int64_t>(batch, 1, blocks);
    PieceResults r(batch * kBandBlockPoints);
    DeviceBuffer<uint32_t> band_mask{size_t(batch) * kBandBlockPoints / 32};  // 64 bytes a block: within the 20% left free
    DeviceBuffer<float> distance32{float32 ? size_t(batch) * kBandBlockPoints : 0};
    const size_t in_use = device_bytes_in_use();

    // As the dense lattice path (run_slab): the same certificate slack, band and finalize.
    const double coordinate = largest_lattice_coordinate(lattice);
    const StreamedCertify fused = streamed_certify(dev, kernel_, coordinate);
    const bool winding = dev.winding.view().enabled();
    const FloatSearchBound& bound = mesh().search_bound();
    const double reach = std::is_same_v<T, float> ? bound.sliver_reach_float : bound.sliver_reach_double;
    BandSearch search{width, dev.mesh->view(), winding, winding || solid(), reach};
    // The bounded search and the flood where the sides of points beyond W can be taken from
    // their neighbours: a solid's pseudonormal sign, a band at least one coset spacing wide
    // (flood_band_sides), the warp kernel (the candidates kernel searches every point).
    const bool bounded = kernel_ == BvhGpuKernel::Warp && !winding && solid() && width >= lattice.spacing;
    // The sweep's blocks without a triangle: their point 0's key and nearest triangle (12 bytes a block).
    DeviceBuffer<unsigned long long> block_key{bounded ? size_t(batch) : 0};
    DeviceBuffer<int> block_nearest{bounded ? size_t(batch) : 0};
    // The sweep's bound on Q_d: W with a relative margin of 1e-6 and an absolute one of 2^-30
    // of the coordinates' scale, far above Q_d's rounding in distance terms (about
    // u (|B - P| scale + 8 extent^2) / W, |B - P| <= the mesh's extent <= 16384 W), so that
    // every point the finalize finds within W has its triangle. No sliver reach: Q_d is exact
    // to that, where the float search ranks slivers by their edges.
    double sweep_bound = 0;
    if (bounded) {
        const double scale = coordinate + bound.coordinate;
        search.bound_squared = band_search_bound_squared<T>(width, scale, reach);
        const double r = (width + 0x1p-30 * scale) * (1.0 + 1e-6);
        sweep_bound = r * r;
    }
    DeviceBuffer<unsigned long long> flood_counters{4};
    CUDA_CHECK(cudaMemset(flood_counters.get(), 0, 4 * sizeof(unsigned long long)));
    reset_certificate(dev);
    int64_t batches = 0;
    for (int64_t b0 = 0; b0 < blocks; b0 += batch, ++batches) {
        const int64_t nb = std::min(batch, blocks - b0), n = nb * kBandBlockPoints;
        const BandBlocksPiece piece{lattice, band.layout().grid(), ids.get() + b0, nb};
        const BandBlocksLayout layout{piece};
        compute.begin();
        search_stage.begin();
        if (bounded) {
            // The sweep: the least key per point in the distance array (rewritten by finalize),
            // the least triangle at it in `nearest`.
            auto* key = reinterpret_cast<unsigned long long*>(r.samples.distance.get());
            static_assert(sizeof(double) == sizeof(unsigned long long), "a key per point in the distance array");
            CUDA_CHECK(cudaMemset(key, 0xff, size_t(n) * sizeof(unsigned long long)));
            fill_nearest<<<blocks_for(n, 256), 256>>>(r.nearest.get(), n, INT_MAX);
            CUDA_CHECK_LAUNCH("fill_nearest");
            const int triangles = dev.view.num_triangles;
            const int grid = std::max(1, std::min(triangles, 1 << 20));
            sweep_band_triangles<0><<<grid, kSweepThreads>>>(packed_double(dev), dev.view.triangle_index, triangles, piece,
                                                              sweep_bound, key, r.nearest.get());
            CUDA_CHECK_LAUNCH("sweep_band_triangles (keys)");
            sweep_band_triangles<1><<<grid, kSweepThreads>>>(packed_double(dev), dev.view.triangle_index, triangles, piece,
                                                              sweep_bound, key, r.nearest.get());
            CUDA_CHECK_LAUNCH("sweep_band_triangles (triangles)");
            finish_sweep<<<blocks_for(n, 256), 256>>>(piece, key, r.nearest.get());
            CUDA_CHECK_LAUNCH("finish_sweep");
            // The blocks left without a triangle: their point 0's nearest within W and the
            // block's reach (its far corner 7 sqrt(3) spacings away, 16 taken), for the flood.
            find_unsigned_blocks<<<int(nb), kBandBlockPoints>>>(r.nearest.get(), block_nearest.get());
            CUDA_CHECK_LAUNCH("find_unsigned_blocks");
            CUDA_CHECK(cudaMemset(block_key.get(), 0xff, size_t(nb) * sizeof(unsigned long long)));
            const double r2 = (std::sqrt(sweep_bound) + 16 * lattice.spacing) * (1.0 + 1e-6);
            sweep_block_origins<0><<<grid, kSweepThreads>>>(packed_double(dev), dev.view.triangle_index, triangles, piece,
                                                             r2 * r2, block_key.get(), block_nearest.get());
            CUDA_CHECK_LAUNCH("sweep_block_origins (keys)");
            sweep_block_origins<1><<<grid, kSweepThreads>>>(packed_double(dev), dev.view.triangle_index, triangles, piece,
                                                             r2 * r2, block_key.get(), block_nearest.get());
            CUDA_CHECK_LAUNCH("sweep_block_origins (triangles)");
        } else {
            fill_nearest<<<blocks_for(n, 256), 256>>>(r.nearest.get(), n, kOutsideBandOutside);
            CUDA_CHECK_LAUNCH("fill_nearest");
            const int grid = blocks_for(layout.threads(), kBvhThreads);
            if (kernel_ == BvhGpuKernel::Warp) {
                launch_bvh_warp(grid, dev.view, layout, search, fused, r.nearest.get());
            } else {
                nearest_triangle_bvh_candidates<T><<<grid, kBvhThreads>>>(dev.view, layout, search, r.nearest.get(), nullptr);
            }
            CUDA_CHECK_LAUNCH("nearest_triangle_bvh (band blocks)");
            if (!fused.exact) certify(dev, piece, coordinate, r.nearest.get());
        }
        search_stage.end();
        finalize_stage.begin();
        PieceOutputs outputs = r.outputs();
        if (!band.channels.gradient) outputs.gradient = nullptr;  // not written: 24 of a point's 36 bytes
        launch_finalize_samples(n, dev.mesh->view(), piece, r.nearest.get(), dev.winding.view(), width, outputs);
        CUDA_CHECK_LAUNCH("finalize_samples (band blocks)");
        finalize_stage.end();
        flood_stage.begin();
        if (bounded) {
            flood_band_sides<T><<<int(nb), kBandBlockPoints>>>(dev.view, dev.mesh->view(), piece, r.nearest.get(),
                                                               bounded ? block_nearest.get() : nullptr, width,
                                                               r.samples.distance.get(), flood_counters.get());
            CUDA_CHECK_LAUNCH("flood_band_sides");
        }
        to_source_order<<<blocks_for(n, 256), 256>>>(r.samples.triangle.get(), n, dev.source_triangle.get());
        CUDA_CHECK_LAUNCH("to_source_order");
        mark_band_points<<<blocks_for(n, 256), 256>>>(r.samples.triangle.get(), n, band_mask.get());
        CUDA_CHECK_LAUNCH("mark_band_points");
        if (float32) {
            round_to_float32<<<blocks_for(n, 256), 256>>>(r.samples.distance.get(), n, distance32.get());
            CUDA_CHECK_LAUNCH("round_to_float32");
        }
        flood_stage.end();
        compute.end();
        download.begin();
        const size_t v = (first + size_t(b0)) * kBandBlockPoints;
        if (float32) staged_.to_host(distance32.get(), band.distance.values<float>() + v, size_t(n) * sizeof(float));
        else staged_.to_host(r.samples.distance.get(), band.distance.values<double>() + v, size_t(n) * sizeof(double));
        if (band.channels.gradient)  // else the band holds none: 24 bytes a point stay on the device
            staged_.to_host(r.samples.gradient.get(), band.gradient.data() + v, size_t(n) * sizeof(Vec3d));
        if (band.channels.closest_triangle)  // else 4 bytes a point stay: the mask marks the band's points
            staged_.to_host(r.samples.triangle.get(), band.closest_triangle.data() + v, size_t(n) * sizeof(int32_t));
        staged_.to_host(band_mask.get(), band.band_mask.data() + first + size_t(b0), size_t(nb) * sizeof(BandPointMask));
        download.end();
    }
    unsigned long long flood[4] = {0, 0, 0, 0};
    CUDA_CHECK(cudaMemcpy(flood, flood_counters.get(), sizeof(flood), cudaMemcpyDeviceToHost));
    if (flood[2] != 0)
        throw std::logic_error("CUDA BVH sparse band: " + std::to_string(flood[2]) +
                               " points beyond the band were left without a side by the flood");
    CertificateCounters certificate;
    read_certificate(dev, certificate);
    band.timings.upload += upload.seconds();
    band.timings.kernel += compute.seconds();
    band.timings.download += download.seconds();
    band.timings.certified_points += certificate.points.load();
    band.timings.reranked_points += certificate.reranked.load();
    band.timings.full_double_points += certificate.full_double.load();
    band.sampler.details["band_blocks_on_device"] = {
        {"kernel", kernel_ == BvhGpuKernel::Warp ? "warp" : "candidates"},
        {"blocks", blocks},
        {"blocks_per_batch", batch},
        {"batches", batches},
        {"brick_skip", search.skip_bricks},
        {"bounded_search", bounded},
        {"nearest", bounded ? "triangle_sweep" : "search"},
        {"distance_type", band_distance_type(band.distance.type()).name},
        {"points_flooded", int64_t(flood[0])},
        {"blocks_signed_by_a_search", int64_t(flood[1])},
        {"blocks_signed_over_every_triangle", int64_t(flood[3])},
        {"kernel_seconds", compute.seconds()},
        {"stage_seconds", {{"search", search_stage.seconds()}, {"finalize", finalize_stage.seconds()},
                           {"flood_source_order_and_mask", flood_stage.seconds()}}},
        {"upload_seconds", upload.seconds()},
        {"download_seconds", download.seconds()},
        {"device_bytes_in_use", int64_t(in_use)},  // after the batch's buffers: the conversion's peak (pool included)
        {"device", describe_device(options_.device)}};
}

}  // namespace sdf::cuda
