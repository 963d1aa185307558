/// @file tuned_kernel.cuh
/// @brief The tuned brute-force search for the nearest triangle on Hopper-class GPUs.
///
/// Per pair it evaluates the branch-free squared_distance() of packed_triangle.h (about 45
/// FP32 instructions). Triangles are staged in shared-memory tiles and read back as warp-wide
/// broadcasts; each thread owns K points, so a triangle loaded once serves K pairs; the
/// triangle list is split across blockIdx.y when there are too few points to fill the GPU,
/// and the splits' minima are merged afterwards (lowest index wins ties, like the CPU).
#pragma once

#include "kernels/distance/packed_triangle.h"

namespace sdf::cuda {

constexpr int kTunedThreads = 128;
constexpr int kTunedTile = 128;  ///< triangles per shared tile (14 KiB in float)

template <typename T, int K, typename Piece>
__global__ void __launch_bounds__(kTunedThreads)
    nearest_triangle_tuned(Piece piece, const PackedTriangle<T>* __restrict__ triangles, int num_triangles,
                           int triangle_offset, int triangles_per_split, T* partial_q, int* partial_index) {
    __shared__ PackedTriangle<T> tile[kTunedTile];
    const int64_t n = piece.size();
    const int64_t first = int64_t(blockIdx.x) * (kTunedThreads * K) + threadIdx.x;

    T px[K], py[K], pz[K], best[K];
    int best_index[K];
#pragma unroll
    for (int k = 0; k < K; ++k) {
        const int64_t i = first + int64_t(k) * kTunedThreads;
        const Vec3<T> p(piece.position(i < n ? i : n - 1));
        px[k] = p.x; py[k] = p.y; pz[k] = p.z;
        best[k] = T(INFINITY);
        best_index[k] = -1;
    }

    const int split_begin = int(blockIdx.y) * triangles_per_split;
    const int split_end = min(num_triangles, split_begin + triangles_per_split);
    for (int t0 = split_begin; t0 < split_end; t0 += kTunedTile) {
        const int count = min(kTunedTile, split_end - t0);
        // Stage the tile with 16-byte loads (PackedTriangle is a multiple of 16 bytes).
        __syncthreads();
        const int words = count * int(sizeof(PackedTriangle<T>) / sizeof(int4));
        const int4* src = reinterpret_cast<const int4*>(triangles + t0);
        int4* dst = reinterpret_cast<int4*>(tile);
        for (int w = threadIdx.x; w < words; w += kTunedThreads) dst[w] = src[w];
        __syncthreads();

        for (int j = 0; j < count; ++j) {
            const PackedTriangle<T> tri = tile[j];  // same address for the whole warp: broadcast
#pragma unroll
            for (int k = 0; k < K; ++k) {
                const T q = squared_distance(tri, px[k], py[k], pz[k]);
                if (q < best[k]) {
                    best[k] = q;
                    best_index[k] = triangle_offset + t0 + j;
                }
            }
        }
    }

#pragma unroll
    for (int k = 0; k < K; ++k) {
        const int64_t i = first + int64_t(k) * kTunedThreads;
        if (i < n) {
            partial_q[int64_t(blockIdx.y) * n + i] = best[k];
            partial_index[int64_t(blockIdx.y) * n + i] = best_index[k];
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
