/// @file bvh_kernel.cuh
/// @brief The GPU nearest-triangle searches over the BVH (kernels/bvh), before the shared
/// double-precision finalize_samples() step of finalize_kernel.cuh.
///
/// Lattice pieces are slabs of whole z-layers of a GridBlock. Threads are laid out so that
/// the 32 threads of a warp query a compact 8 x 4 x 4 brick of lattice points (each thread
/// a run of kRunPoints = 4 consecutive points along x): neighbouring threads walk nearly
/// the same nodes, which keeps the warp converged and the node loads shared in L1.
///   kernel "brick":    the thread's 4 points share one packet traversal (K = 4);
///   kernel "seeded":   the 4 points one after the other, each seeded with the previous
///                      point's triangle (an exact upper bound on its distance);
///   kernel "unseeded": the same without seeds;
///   kernel "warp":     the warp's 128 points share one traversal (bvh_warp_kernel.cuh).
/// Point lists are sorted into Morton order and take the warp or the candidates kernel
/// (bvh_point_query.cu).
#pragma once

#include "kernels/bvh/closest_triangle_bvh.h"
#include "kernels/bvh/closest_triangles_packet.h"
#include "cuda/bvh/bvh_sampler.h"
#include "cuda/sampling/point_pieces.h"

namespace sdf::cuda {

constexpr int kRunPoints = 4;       ///< lattice points per thread, consecutive along x
constexpr int kBvhThreads = 128;    ///< threads per block (4 warps)

/// A slab of z-layers [z0, z0 + nz) of one GridBlock; piece-local ids run x fastest, as in
/// GridRangePiece (whose begin = z0 * rx * ry), so finalize_samples() takes it as is.
struct SlabGeometry {
    Int3 resolution{};  ///< the block's
    int z0 = 0, nz = 0;
    SDF_CPU_GPU int runs_x() const { return (resolution.x + kRunPoints - 1) / kRunPoints; }
    /// Warps per axis: a warp covers 2 runs (8 points) x 4 rows x 4 layers.
    SDF_CPU_GPU Int3 warps() const { return {(runs_x() + 1) / 2, (resolution.y + 3) / 4, (nz + 3) / 4}; }
    SDF_CPU_GPU int64_t threads() const {
        const Int3 w = warps();
        return int64_t(w.x) * w.y * w.z * 32;
    }
    /// The first point (x, y, slab-local z) of thread t's run.
    SDF_CPU_GPU Int3 run_start(int64_t t) const {
        const Int3 w = warps();
        const int64_t warp = t / 32;
        const int lane = int(t % 32);
        const int wx = int(warp % w.x), wy = int((warp / w.x) % w.y), wz = int(warp / (int64_t(w.x) * w.y));
        return {(wx * 2 + (lane & 1)) * kRunPoints, wy * 4 + ((lane >> 1) & 3), wz * 4 + (lane >> 3)};
    }
};

/// Nearest triangle (prepared-mesh index) of every point of a lattice slab.
template <typename T, BvhGpuKernel kKernel>
__global__ void __launch_bounds__(kBvhThreads) nearest_triangle_bvh_slab(BvhView<T> bvh, GridRangePiece piece,
                                                                          SlabGeometry slab, int* nearest) {
    const int64_t t = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (t >= slab.threads()) return;
    const Int3 s = slab.run_start(t);
    if (s.x >= slab.resolution.x || s.y >= slab.resolution.y || s.z >= slab.nz) return;
    const int count = min(kRunPoints, slab.resolution.x - s.x);
    const int64_t first = s.x + int64_t(slab.resolution.x) * (s.y + int64_t(slab.resolution.y) * s.z);  // piece-local
    if constexpr (kKernel == BvhGpuKernel::Brick) {
        BvhPacket<T, kRunPoints> pk;
        int32_t seed[kRunPoints];
        for (int k = 0; k < kRunPoints; ++k) {
            const Vec3<T> p(piece.position(first + (k < count ? k : 0)));
            pk.x[k] = p.x; pk.y[k] = p.y; pk.z[k] = p.z;
            seed[k] = -1;
        }
        seed_packet(bvh, seed, pk);
        NoBvhStats none;
        closest_triangles_packet(bvh, pk, none);
        for (int k = 0; k < count; ++k) nearest[first + k] = bvh.triangle_index[pk.best_slot[k]];
    } else {
        int32_t previous = -1;
        for (int k = 0; k < count; ++k) {
            const Vec3<T> p(piece.position(first + k));
            const BvhHit<T> seed = kKernel == BvhGpuKernel::Seeded ? seed_hit(bvh, previous, p) : BvhHit<T>{};
            const BvhHit<T> hit = closest_triangle_bvh(bvh, p, seed);
            previous = hit.slot;
            nearest[first + k] = bvh.triangle_index[hit.slot];
        }
    }
}

}  // namespace sdf::cuda
