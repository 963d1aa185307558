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
// (finish_band_blocks, band_sides.h), a block of such points from its point 0's double-search
// triangle. Every other band runs the search.
#include <algorithm>
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
#include "kernels/lattice/band_sweep.h"

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

/// Whether point p is inside by the pseudonormal sign at its double-search triangle (the
/// points' reference, exact where a float search may tie across a thin part): the side of a
/// block whose points all lie beyond the band.
__device__ SDF_INLINE bool inside_by_double_search(const BvhView<double>& exact, const MeshView<double>& mesh, Vec3d p) {
    const int32_t slot = double_search_slot(exact, p, -1);
    return signed_distance_to_triangle(mesh, p, exact.triangle_index[slot]).distance < 0;
}

/// The last pass over a batch's blocks after finalize, a warp per block, 16 points a lane
/// (point 32 j + lane at step j: coalesced): the closest triangles to the mesh file's face
/// order, the band's points as the block's mask (SparseBandField::band_mask: bit `local` set
/// where the triangle is not kOutsideBandTriangle; step j's ballot is the mask's 32-bit half j,
/// little-endian, as the host reads it), the distances rounded to float32 where the band holds
/// them so (float(d), as the host type rounds them: half the download), and with kSpread the
/// sides of the points the sweep left without a triangle (kOutsideBandFlood): band_sides.h's
/// layers, lane s * 8 + z holding side s's layer z (bits 32 (j & 1) + lane of layer j / 2 at
/// step j), spread a step at a time with the layers below and above shuffled in; a block of
/// such points starts from its point 0's side (`block_side`: sides_of_unsigned_blocks).
/// counters[0]: points spread to; counters[2]: points left without one side (reached by both:
/// pseudonormal sides that disagree, which the host refuses).
constexpr int kFinishThreads = 256;
constexpr int kFinishBlocksPerCudaBlock = kFinishThreads / 32;

template <bool kSpread>
__global__ void __launch_bounds__(kFinishThreads)
    finish_band_blocks(BandBlocksPiece piece, const int* nearest, const signed char* block_side, double width, double* distance,
                       float* distance32, Vec3d* gradient, int* triangle, const int32_t* source_triangle, uint32_t* mask,
                       unsigned long long* counters) {
    constexpr int kSteps = kBandBlockPoints / 32;
    const int lane = threadIdx.x & 31;
    const int64_t a = int64_t(blockIdx.x) * kFinishBlocksPerCudaBlock + threadIdx.x / 32;
    if (a >= piece.blocks) return;  // the whole warp
    const int64_t base = a * kBandBlockPoints;
    const Int3 points = piece.grid.block_points(piece.grid.block_coords(piece.ids[a]));
    const int z = lane & (kBandBlockDim - 1);
    const bool inside_lane = lane < kBandBlockDim, layer_lane = lane < 2 * kBandBlockDim;
    uint64_t layer = 0, open = 0;  // side (lane / 8)'s layer z, and layer z's open points
    int flooded = 0;               // the block's open points (uniform)
    double d[kSteps];
#pragma unroll
    for (int j = 0; j < kSteps; ++j) {
        const int64_t i = base + 32 * j + lane;
        // An open point's outputs are this pass's (finalize leaves them): outside the band;
        // padding the sweep did not reach (never, being beyond the coset) likewise, +W.
        const bool flood = kSpread && nearest[i] == kOutsideBandFlood;
        const int t = flood ? kOutsideBandTriangle : triangle[i];
        const unsigned in_band = __ballot_sync(kFullWarp, t != kOutsideBandTriangle);
        if (lane == 0) mask[a * kSteps + j] = in_band;
        if (t >= 0) triangle[i] = source_triangle[t];
        if (flood) {
            triangle[i] = kOutsideBandTriangle;
            if (gradient) gradient[i] = Vec3d(0.0);
        }
        d[j] = flood || !(kSpread || distance32 != nullptr) ? width : distance[i];  // an open point's: spread below
        if constexpr (kSpread) {
            const int local = 32 * j + lane;
            const bool real = BandBlockGrid::within(points, local);  // padding: never open
            if (flood && !real && distance32 == nullptr) distance[i] = width;
            const bool negative = !flood && signbit(d[j]);
            const unsigned in = __ballot_sync(kFullWarp, real && !flood && negative);
            const unsigned out = __ballot_sync(kFullWarp, real && !flood && !negative);
            const unsigned fl = __ballot_sync(kFullWarp, real && flood);
            flooded += __popc(fl);
            if ((j >> 1) == z) {
                const int shift = 32 * (j & 1);
                if (layer_lane) layer |= uint64_t(inside_lane ? in : out) << shift;
                open |= uint64_t(fl) << shift;
            }
        }
    }
    if constexpr (kSpread) {
        if (!layer_lane) open = 0;
        if (flooded > 0) {
            if (!__any_sync(kFullWarp, layer != 0) && z == 0 && layer_lane)  // no point with its own side: point 0's
                layer = block_side[a] == (inside_lane ? kBandSideInside : kBandSideOutside) ? 1 : 0;
            for (;;) {
                const uint64_t below = __shfl_sync(kFullWarp, layer, z > 0 ? lane - 1 : lane);
                const uint64_t above = __shfl_sync(kFullWarp, layer, z + 1 < kBandBlockDim ? lane + 1 : lane);
                const uint64_t reached = band_layer_step(layer, z > 0 ? below : 0, z + 1 < kBandBlockDim ? above : 0) & open & ~layer;
                layer |= reached;
                if (!__any_sync(kFullWarp, reached != 0)) break;
            }
            const uint64_t other = __shfl_xor_sync(kFullWarp, layer, kBandBlockDim);  // the other side's layer z
            const uint64_t wrong = (open & ~(layer | other)) | (layer & other);
            int unsided = inside_lane ? __popcll(wrong) : 0;
            for (int o = 16; o > 0; o >>= 1) unsided += __shfl_xor_sync(kFullWarp, unsided, o);
#pragma unroll
            for (int j = 0; j < kSteps; ++j) {
                const uint64_t in = __shfl_sync(kFullWarp, layer, j >> 1), fl = __shfl_sync(kFullWarp, open, j >> 1);
                const int bit = 32 * (j & 1) + lane;
                if ((fl >> bit) & 1) {
                    d[j] = ((in >> bit) & 1) ? -width : width;
                    if (distance32 == nullptr) distance[base + 32 * j + lane] = d[j];
                }
            }
            if (lane == 0) {
                atomicAdd(counters + 0, (unsigned long long)flooded);
                if (unsided > 0) atomicAdd(counters + 2, (unsigned long long)unsided);
            }
        }
    }
    if (distance32 != nullptr) {
#pragma unroll
        for (int j = 0; j < kSteps; ++j) distance32[base + 32 * j + lane] = float(d[j]);
    }
}

/// The triangle sweep (kernels/lattice/band_sweep.h; a solid's bounded band, in place of the
/// bounded search): each triangle walks the columns of its box dilated by the bound, each point
/// keeps the least (Q_d, triangle index) within the bound, and a point left without one is
/// kOutsideBandFlood (the flood's). Two passes: the least Q_d as an ordered 64-bit key
/// (atomicMin), then the least triangle index among the triangles at that key. (One pass by
/// sm_90's 16-byte compare-and-swap of key and index was twice as slow: a compare-and-swap
/// waits for its answer, where an atomicMin whose result is unused is a reduction that does
/// not; docs/large-lattices.md.) Work grows with the band's points near each triangle, not with
/// a search per point of every active block (3-6 times the band's points).
enum SweepPass : int { kSweepKeys = 0, kSweepTriangles = 1 };
constexpr int kSweepThreads = 128;
/// Blocks per SM of the band's finalize (launch_finalize_samples): capped at 64 registers it
/// took 6.5 ms at 4096^3 and 25.6 ms at 8192^3 on an H200, where it took 11.8 and 46.0 ms at
/// its own 100 (2 blocks) and 8.2 and 32.0 ms at 3 blocks.
constexpr int kBandFinalizeMinBlocks = 4;
/// Blocks of a triangle's box whose batch indices are kept in shared memory; a larger box
/// (a triangle many blocks wide) looks each point's block up in the sorted ids instead.
constexpr int kSweepCachedBlocks = 2048;

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

template <SweepPass kPass>
__global__ void __launch_bounds__(kSweepThreads, 6)
    sweep_band_triangles(const PackedTriangle<double>* packed, const int32_t* triangle_index, int triangles,
                         BandBlocksPiece piece, double bound_squared, unsigned long long* best_key, int* best_triangle,
                         unsigned char* block_reached) {
    __shared__ int64_t cached[kSweepCachedBlocks];
    const double reach = sqrt(bound_squared);
    for (int s = blockIdx.x; s < triangles; s += gridDim.x) {
        const PackedTriangle<double> t = packed[s];
        const int triangle = triangle_index[s];
        Vec3d lo, hi;
        dilated_box(t, reach, lo, hi);
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
            // Columns along the normal's largest axis, each walked only where it crosses the
            // slab |h| <= R (h linear along it; R bounds beyond_plane's threshold over the
            // box, one point of margin for the rounding): most of a large triangle's box lies
            // beyond its slab. beyond_plane still decides each point, so the range only has to
            // hold every point it keeps. A normal of zero or NaN walks whole columns.
            const Vec3d n(t.nx, t.ny, t.nz);
            const int ax = fabs(n.x) >= fabs(n.y) && fabs(n.x) >= fabs(n.z) ? 0 : fabs(n.y) >= fabs(n.z) ? 1 : 2;
            const int au = ax == 0 ? 1 : 0, av = ax == 2 ? 1 : 2;
            const double hh = piece.lattice.half_spacing();
            const Vec3d span = hi - lo;
            const double slab = sweep_slab_half_width(bound_squared, span);  // R
            const double n_ax = n[ax];
            const bool sloped = fabs(n_ax) >= 0.5;  // a unit normal's largest component is >= 1/sqrt(3)
            const Int3 r0 = p0, r1 = p1;  // read only (a write through Int3::operator[] would put them in local memory)
            const int nu = r1[au] - r0[au] + 1;
            const int64_t columns = int64_t(nu) * (r1[av] - r0[av] + 1);
            const Int3 step{ax == 0, ax == 1, ax == 2};
            for (int64_t j = threadIdx.x; j < columns; j += blockDim.x) {
                const int u = r0[au] + int(j % nu), v = r0[av] + int(j / nu);
                int first = r0[ax], last = r1[ax];
                if (sloped) {
                    // h = n . (B - x) = k - n_ax x_ax, with x_ax = origin + hh (first + 2 p_ax).
                    const double xu = piece.lattice.origin[au] + hh * double(coset.first[au] + 2 * u);
                    const double xv = piece.lattice.origin[av] + hh * double(coset.first[av] + 2 * v);
                    const double k = n.x * t.bx + n.y * t.by + n.z * t.bz - n[au] * xu - n[av] * xv;
                    const double e0 = (k - slab) / n_ax, e1 = (k + slab) / n_ax;  // x_ax's ends, either order
                    const double c0 = ((fmin(e0, e1) - piece.lattice.origin[ax]) / hh - coset.first[ax]) / 2;
                    const double c1 = ((fmax(e0, e1) - piece.lattice.origin[ax]) / hh - coset.first[ax]) / 2;
                    if (c0 - 1 > double(first)) first = c0 - 1 > double(last) ? last + 1 : int(floor(c0)) - 1;
                    if (c1 + 1 < double(last)) last = c1 + 1 < double(first) ? first - 1 : int(ceil(c1)) + 1;
                }
                Int3 p{ax == 0 ? first : u, ax == 0 ? u : ax == 1 ? first : v, ax == 2 ? first : v};
                for (int along = first; along <= last; ++along, p.x += step.x, p.y += step.y, p.z += step.z) {
                    const Int3 pb{p.x >> kBandBlockLog2, p.y >> kBandBlockLog2, p.z >> kBandBlockLog2};
                    const int64_t a = use_cache ? cached[(pb.x - b0.x) + int64_t(nb.x) * ((pb.y - b0.y) + int64_t(nb.y) * (pb.z - b0.z))]
                                                : batch_index(piece, piece.grid.block_id(c, pb));
                    if (a < 0) continue;  // not an active block of this batch
                    const Vec3d x =
                        piece.lattice.position_of_coords({coset.first.x + 2 * p.x, coset.first.y + 2 * p.y, coset.first.z + 2 * p.z});
                    if (beyond_plane(t, x, bound_squared)) continue;
                    double q = squared_distance(t, x.x, x.y, x.z);
                    if (!(q <= bound_squared)) continue;
                    if (q == 0) q = 0;  // -0 ties +0, as the search's comparison
                    const int64_t i = a * kBandBlockPoints + (p.x & (kBandBlockDim - 1)) +
                                      kBandBlockDim * ((p.y & (kBandBlockDim - 1)) + kBandBlockDim * (p.z & (kBandBlockDim - 1)));
                    const unsigned long long key = ordered_key(q);
                    if constexpr (kPass == kSweepKeys) {
                        if (key < best_key[i]) atomicMin(best_key + i, key);  // a stale read only costs an atomic
                    } else if (key == best_key[i]) {
                        atomicMin(best_triangle + i, triangle);
                        block_reached[a] = 1;  // every writer writes 1
                    }
                }
            }
            if (use_cache) __syncthreads();  // before the next box overwrites the cache
        }
    }
}

/// The blocks no triangle reached (none of their points within the sweep's bound: every point
/// beyond the band), listed in `unsigned_blocks` (count in `unsigned_count`): each takes its
/// point 0's side (sides_of_unsigned_blocks). A thread per block. (The points the sweep left
/// without a triangle keep kOutsideBandFlood from the fill, padding included: finalize leaves
/// them to finish_band_blocks.)
__global__ void list_unreached_blocks(const unsigned char* block_reached, int64_t blocks, int32_t* unsigned_blocks,
                                      unsigned int* unsigned_count) {
    const int64_t a = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (a < blocks && !block_reached[a]) unsigned_blocks[atomicAdd(unsigned_count, 1u)] = int32_t(a);
}

/// The side of each listed block (no point with a triangle: every point beyond the band), as
/// its point 0's by the double search (inside_by_double_search), a thread per block, striding
/// over the list (its length is on the device). counters[1]: blocks signed so.
__global__ void sides_of_unsigned_blocks(BvhView<double> exact, MeshView<double> mesh, BandBlocksPiece piece,
                                         const int32_t* unsigned_blocks, const unsigned int* unsigned_count, signed char* block_side,
                                         unsigned long long* counters) {
    const unsigned count = *unsigned_count;
    for (unsigned k = blockIdx.x * blockDim.x + threadIdx.x; k < count; k += gridDim.x * blockDim.x) {
        const int32_t a = unsigned_blocks[k];
        block_side[a] = inside_by_double_search(exact, mesh, piece.position(int64_t(a) * kBandBlockPoints)) ? kBandSideInside
                                                                                                            : kBandSideOutside;
        atomicAdd(counters + 1, 1ull);
    }
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
    EventTimer search_stage, finalize_stage, sides_stage;  // compute's parts
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
    BandSearch search{width, dev.mesh->view(), winding, winding || solid(), reach, double_view(dev, bound)};
    // The sweep and the spread of sides where the sides of points beyond W can be taken from
    // their neighbours: a solid's pseudonormal sign, a band at least one coset spacing wide
    // (band_sides.h), the warp kernel (the candidates kernel searches every point).
    const bool swept = kernel_ == BvhGpuKernel::Warp && !winding && solid() && width >= lattice.spacing;
    // The blocks the sweep leaves without a triangle: their list, sides and marks (6 bytes a block).
    DeviceBuffer<int32_t> unsigned_blocks{swept ? size_t(batch) : 0};
    DeviceBuffer<signed char> block_side{swept ? size_t(batch) : 0};
    DeviceBuffer<unsigned char> block_reached{swept ? size_t(batch) : 0};
    DeviceBuffer<unsigned int> unsigned_count{1};
    const double sweep_bound = swept ? band_sweep_bound_squared(width, coordinate + bound.coordinate) : 0.0;
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
        if (swept) {
            const int triangles = dev.view.num_triangles;
            const int grid = std::max(1, std::min(triangles, 1 << 20));
            // The least key per point in the distance array (rewritten by finalize), the least
            // triangle at it in `nearest`.
            auto* key = reinterpret_cast<unsigned long long*>(r.samples.distance.get());
            static_assert(sizeof(double) == sizeof(unsigned long long), "a key per point in the distance array");
            CUDA_CHECK(cudaMemset(key, 0xff, size_t(n) * sizeof(unsigned long long)));  // all ones: above every key
            fill_nearest<<<blocks_for(n, 256), 256>>>(r.nearest.get(), n, kOutsideBandFlood);
            CUDA_CHECK_LAUNCH("fill_nearest");
            CUDA_CHECK(cudaMemset(block_reached.get(), 0, size_t(nb)));
            sweep_band_triangles<kSweepKeys><<<grid, kSweepThreads>>>(packed_double(dev), dev.view.triangle_index, triangles,
                                                                        piece, sweep_bound, key, r.nearest.get(), nullptr);
            CUDA_CHECK_LAUNCH("sweep_band_triangles (keys)");
            sweep_band_triangles<kSweepTriangles><<<grid, kSweepThreads>>>(
                packed_double(dev), dev.view.triangle_index, triangles, piece, sweep_bound, key, r.nearest.get(), block_reached.get());
            CUDA_CHECK_LAUNCH("sweep_band_triangles (triangles)");
            CUDA_CHECK(cudaMemset(unsigned_count.get(), 0, sizeof(unsigned int)));
            list_unreached_blocks<<<blocks_for(nb, 256), 256>>>(block_reached.get(), nb, unsigned_blocks.get(), unsigned_count.get());
            CUDA_CHECK_LAUNCH("list_unreached_blocks");
            sides_of_unsigned_blocks<<<std::max<int64_t>(1, std::min<int64_t>(blocks_for(nb, 128), 1024)), 128>>>(
                search.exact, dev.mesh->view(), piece, unsigned_blocks.get(), unsigned_count.get(), block_side.get(),
                flood_counters.get());
            CUDA_CHECK_LAUNCH("sides_of_unsigned_blocks");
        } else {
            fill_nearest<<<blocks_for(n, 256), 256>>>(r.nearest.get(), n, kOutsideBandOutside);
            CUDA_CHECK_LAUNCH("fill_nearest");
            if (kernel_ == BvhGpuKernel::Warp) {
                launch_bvh_warp(dev.view, layout, search, fused, r.nearest.get(), {}, warp_queue());
            } else {
                nearest_triangle_bvh_candidates<T><<<blocks_for(layout.threads(), kBvhThreads), kBvhThreads>>>(dev.view, layout, search, r.nearest.get(), nullptr);
            }
            CUDA_CHECK_LAUNCH("nearest_triangle_bvh (band blocks)");
            if (!fused.exact) certify(dev, piece, coordinate, r.nearest.get());
        }
        search_stage.end();
        finalize_stage.begin();
        PieceOutputs outputs = r.outputs();
        if (!band.channels.gradient) outputs.gradient = nullptr;  // not written: 24 of a point's 36 bytes
        outputs.output_index = nullptr;  // block-major: point i is slot i
        launch_finalize_samples<kBandFinalizeMinBlocks>(n, dev.mesh->view(), piece, r.nearest.get(), dev.winding.view(), width,
                                                        outputs);
        CUDA_CHECK_LAUNCH("finalize_samples (band blocks)");
        finalize_stage.end();
        sides_stage.begin();
        const auto finish = [&](auto spread) {
            finish_band_blocks<decltype(spread)::value><<<blocks_for(nb, kFinishBlocksPerCudaBlock), kFinishThreads>>>(
                piece, r.nearest.get(), block_side.get(), width, r.samples.distance.get(), float32 ? distance32.get() : nullptr,
                outputs.gradient, r.samples.triangle.get(), dev.source_triangle.get(), band_mask.get(), flood_counters.get());
        };
        if (swept) finish(std::true_type{});
        else finish(std::false_type{});
        CUDA_CHECK_LAUNCH("finish_band_blocks");
        sides_stage.end();
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
    if (flood[2] != 0)  // neighbours beyond the band on opposite sides
        throw std::runtime_error("CUDA BVH sparse band: " + mesh().name() + ": " + std::to_string(flood[2]) +
                                 " points beyond the band have neighbours on both sides by the pseudonormal sign, which "
                                 "is not consistent there (slivers within the search's rounding of a sharp edge?); "
                                 "sample this mesh with the winding sign (--sign winding, sampler \"sign\": \"winding\")");
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
        {"bounded_search", swept},
        {"nearest", swept ? "triangle_sweep" : "search"},
        {"distance_type", band_distance_type(band.distance.type()).name},
        {"points_flooded", int64_t(flood[0])},
        {"blocks_signed_by_a_search", int64_t(flood[1])},
        {"kernel_seconds", compute.seconds()},
        {"stage_seconds", {{"search", search_stage.seconds()}, {"finalize", finalize_stage.seconds()},
                           {"sides_source_order_and_mask", sides_stage.seconds()}}},
        {"upload_seconds", upload.seconds()},
        {"download_seconds", download.seconds()},
        {"device_bytes_in_use", int64_t(in_use)},  // after the batch's buffers: the conversion's peak (pool included)
        {"device", describe_device(options_.device)}};
}

}  // namespace sdf::cuda
