/// @file tuned_kernel.cuh
/// @brief The tuned brute-force search for the nearest triangle on Hopper-class GPUs.
///
/// Per pair it evaluates the branch-free squared_distance() of packed_triangle.h (42
/// instructions on sm_90, 1 more to keep the minimum). Triangles are staged in shared-memory tiles and read back as warp-wide
/// broadcasts; each thread owns K points, so a triangle loaded once serves K pairs; the
/// triangle list is split across blockIdx.y when there are too few points to fill the GPU,
/// and the splits' minima are merged afterwards (lowest index wins ties, like the CPU).
#pragma once

#include "kernels/distance/packed_triangle.h"

namespace sdf::cuda {

constexpr int kTunedThreads = 128;
constexpr int kTunedTile = 128;  ///< triangles per shared tile (12 KiB in float)

/// Triangles per group: the inner loop keeps only each point's minimum (one FMNMX a pair);
/// after every group it notes which group improved the minimum, and at the end the winning
/// group is searched again for the triangle's index. That saves two instructions a pair
/// (compare and select of the index) for 16 extra evaluations per point.
constexpr int kTunedGroup = 16;

template <typename T, int K>
struct PointRegisters {
    T x[K], y[K], z[K], best[K];
    int group[K];  ///< first triangle of the group that holds the minimum, -1 before any

    /// Evaluates triangles [0, count) of `tile` (global indices first..) for all K points.
    SDF_INLINE __device__ void visit_tile(const PackedTriangle<T>* tile, int count, int first) {
        for (int j0 = 0; j0 < count; j0 += kTunedGroup) {
            T before[K];
#pragma unroll
            for (int k = 0; k < K; ++k) before[k] = best[k];
            const int n = min(kTunedGroup, count - j0);
            for (int j = j0; j < j0 + n; ++j) {
                const PackedTriangle<T> tri = tile[j];  // same address for the whole warp: broadcast
#pragma unroll
                for (int k = 0; k < K; ++k) best[k] = min_of(best[k], squared_distance(tri, x[k], y[k], z[k]));
            }
#pragma unroll
            for (int k = 0; k < K; ++k) group[k] = best[k] < before[k] ? first + j0 : group[k];
        }
    }
};

/// The index of the nearest of triangles [group, group + kTunedGroup) ∩ [.., end) to p,
/// and its squared distance (first on ties).
template <typename T>
__device__ int nearest_in_group(const PackedTriangle<T>* triangles, int group, int end, T px, T py, T pz, T& q) {
    int index = -1;
    q = T(INFINITY);
    for (int j = group; j < min(group + kTunedGroup, end); ++j) {
        const T d = squared_distance(triangles[j], px, py, pz);
        if (d < q) {
            q = d;
            index = j;
        }
    }
    return index;
}

/// Copies `count` packed triangles to shared memory with 16-byte words.
template <typename T>
__device__ void stage_tile(PackedTriangle<T>* tile, const PackedTriangle<T>* src, int count) {
    const int words = count * int(sizeof(PackedTriangle<T>) / sizeof(int4));
    int4* dst = reinterpret_cast<int4*>(tile);
    const int4* from = reinterpret_cast<const int4*>(src);
    for (int w = threadIdx.x; w < words; w += kTunedThreads) dst[w] = from[w];
}

template <typename T, int K, typename Piece>
__global__ void __launch_bounds__(kTunedThreads, 1)  // 1: let it use ~155 registers (measured fastest)
    nearest_triangle_tuned(Piece piece, const PackedTriangle<T>* __restrict__ triangles, int num_triangles,
                           int triangle_offset, int triangles_per_split, T* partial_q, int* partial_index) {
    __shared__ PackedTriangle<T> tile[kTunedTile];
    const int64_t n = piece.size();
    const int64_t first = int64_t(blockIdx.x) * (kTunedThreads * K) + threadIdx.x;

    PointRegisters<T, K> pts;
#pragma unroll
    for (int k = 0; k < K; ++k) {
        const int64_t i = first + int64_t(k) * kTunedThreads;
        const Vec3<T> p(piece.position(i < n ? i : n - 1));
        pts.x[k] = p.x; pts.y[k] = p.y; pts.z[k] = p.z;
        pts.best[k] = T(INFINITY);
        pts.group[k] = -1;
    }

    // Stage a tile, evaluate it against the K points, repeat. (Double buffering with cp.async,
    // reading triangles straight from global memory, 256-triangle tiles and capping the
    // registers for more resident blocks were all measured no faster on an H200: see
    // docs/gpu-notes.md.)
    const int split_begin = int(blockIdx.y) * triangles_per_split;
    const int split_end = min(num_triangles, split_begin + triangles_per_split);
    for (int t0 = split_begin; t0 < split_end; t0 += kTunedTile) {
        const int count = min(kTunedTile, split_end - t0);
        __syncthreads();
        stage_tile(tile, triangles + t0, count);
        __syncthreads();
        pts.visit_tile(tile, count, t0);
    }

    // Recover each point's triangle from its winning group (global memory, once per point).
#pragma unroll
    for (int k = 0; k < K; ++k) {
        const int64_t i = first + int64_t(k) * kTunedThreads;
        if (i >= n) continue;
        T q = T(INFINITY);
        int index = -1;
        if (pts.group[k] >= 0)
            index = nearest_in_group(triangles, pts.group[k], split_end, pts.x[k], pts.y[k], pts.z[k], q);
        partial_q[int64_t(blockIdx.y) * n + i] = q;
        partial_index[int64_t(blockIdx.y) * n + i] = index < 0 ? -1 : triangle_offset + index;
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
