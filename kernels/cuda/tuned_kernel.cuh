/// @file tuned_kernel.cuh
/// @brief The tuned brute-force search for the nearest triangle on Hopper-class GPUs.
///
/// Per pair it evaluates the branch-free squared_distance() of packed_triangle.h (about 45
/// FP32 instructions). Triangles are staged in shared-memory tiles and read back as warp-wide
/// broadcasts; each thread owns K points, so a triangle loaded once serves K pairs; the
/// triangle list is split across blockIdx.y when there are too few points to fill the GPU,
/// and the splits' minima are merged afterwards (lowest index wins ties, like the CPU).
#pragma once

#include <cuda_pipeline.h>

#include "kernels/distance/packed_triangle.h"

namespace sdf::cuda {

constexpr int kTunedThreads = 128;
constexpr int kTunedTile = 128;  ///< triangles per shared tile (14 KiB in float)

/// How a block gets its triangles: one shared tile at a time; two shared tiles, the next
/// one copied asynchronously (cp.async) while the current one is used; or no shared memory,
/// each warp reading the same triangle straight from global memory (a broadcast L1 load).
enum class TileMode { Shared, DoubleBuffered, Global };

template <typename T, int K>
struct PointRegisters {
    T x[K], y[K], z[K], best[K];
    int index[K];

    /// Evaluates one triangle for all K points and keeps each point's minimum.
    SDF_INLINE __device__ void visit(const PackedTriangle<T>& tri, int triangle_index) {
#pragma unroll
        for (int k = 0; k < K; ++k) {
            const T q = squared_distance(tri, x[k], y[k], z[k]);
            if (q < best[k]) {
                best[k] = q;
                index[k] = triangle_index;
            }
        }
    }
};

/// Copies `count` packed triangles to shared memory with 16-byte words, asynchronously
/// (cp.async) when `async`; the caller commits, waits and synchronises.
template <typename T>
__device__ void stage_tile(PackedTriangle<T>* tile, const PackedTriangle<T>* src, int count, bool async) {
    const int words = count * int(sizeof(PackedTriangle<T>) / sizeof(int4));
    int4* dst = reinterpret_cast<int4*>(tile);
    const int4* from = reinterpret_cast<const int4*>(src);
    for (int w = threadIdx.x; w < words; w += kTunedThreads) {
        if (async) __pipeline_memcpy_async(dst + w, from + w, sizeof(int4));
        else dst[w] = from[w];
    }
}

template <typename T, int K, TileMode Mode, typename Piece>
__global__ void __launch_bounds__(kTunedThreads)
    nearest_triangle_tuned(Piece piece, const PackedTriangle<T>* __restrict__ triangles, int num_triangles,
                           int triangle_offset, int triangles_per_split, T* partial_q, int* partial_index) {
    constexpr int kBuffers = Mode == TileMode::DoubleBuffered ? 2 : (Mode == TileMode::Shared ? 1 : 0);
    __shared__ PackedTriangle<T> tiles[kBuffers > 0 ? kBuffers : 1][kTunedTile];
    const int64_t n = piece.size();
    const int64_t first = int64_t(blockIdx.x) * (kTunedThreads * K) + threadIdx.x;

    PointRegisters<T, K> pts;
#pragma unroll
    for (int k = 0; k < K; ++k) {
        const int64_t i = first + int64_t(k) * kTunedThreads;
        const Vec3<T> p(piece.position(i < n ? i : n - 1));
        pts.x[k] = p.x; pts.y[k] = p.y; pts.z[k] = p.z;
        pts.best[k] = T(INFINITY);
        pts.index[k] = -1;
    }

    const int split_begin = int(blockIdx.y) * triangles_per_split;
    const int split_end = min(num_triangles, split_begin + triangles_per_split);
    if constexpr (Mode == TileMode::Global) {
        // Every lane reads the same triangle: one broadcast load per 16 bytes, no barriers.
#pragma unroll 2
        for (int j = split_begin; j < split_end; ++j) pts.visit(triangles[j], triangle_offset + j);
    } else if constexpr (Mode == TileMode::Shared) {
        for (int t0 = split_begin; t0 < split_end; t0 += kTunedTile) {
            const int count = min(kTunedTile, split_end - t0);
            __syncthreads();
            stage_tile(tiles[0], triangles + t0, count, false);
            __syncthreads();
            for (int j = 0; j < count; ++j) pts.visit(tiles[0][j], triangle_offset + t0 + j);
        }
    } else {
        // Double buffering: the copy of tile i+1 runs while tile i is evaluated.
        if (split_begin < split_end) stage_tile(tiles[0], triangles + split_begin, min(kTunedTile, split_end - split_begin), true);
        __pipeline_commit();
        int buffer = 0;
        for (int t0 = split_begin; t0 < split_end; t0 += kTunedTile, buffer ^= 1) {
            const int count = min(kTunedTile, split_end - t0);
            const int next = t0 + kTunedTile;
            if (next < split_end) stage_tile(tiles[buffer ^ 1], triangles + next, min(kTunedTile, split_end - next), true);
            __pipeline_commit();
            __pipeline_wait_prior(1);  // the current tile has landed
            __syncthreads();
            for (int j = 0; j < count; ++j) pts.visit(tiles[buffer][j], triangle_offset + t0 + j);
            __syncthreads();  // everyone is done with this buffer before it is refilled
        }
    }

#pragma unroll
    for (int k = 0; k < K; ++k) {
        const int64_t i = first + int64_t(k) * kTunedThreads;
        if (i < n) {
            partial_q[int64_t(blockIdx.y) * n + i] = pts.best[k];
            partial_index[int64_t(blockIdx.y) * n + i] = pts.index[k];
        }
    }
}

/// Folds the splits' minima into the running minimum (earlier splits win ties).
template <typename T>
__global__ void merge_partial_minima(int64_t n, int splits, const T* partial_q, const int* partial_index, T* best_q,
                                     int* best_index) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    T q = best_q[i];
    int b = best_index[i];
    for (int s = 0; s < splits; ++s) {
        const T qs = partial_q[int64_t(s) * n + i];
        if (qs < q) {
            q = qs;
            b = partial_index[int64_t(s) * n + i];
        }
    }
    best_q[i] = q;
    best_index[i] = b;
}

template <typename T>
__global__ void fill_minima(int64_t n, T* q, int* index) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    q[i] = T(INFINITY);
    index[i] = -1;
}

}  // namespace sdf::cuda
