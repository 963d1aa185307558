/// @file nearest_triangle_cpu.h
/// @brief The vectorised CPU search for the nearest triangle of a small tile of points.
#pragma once

#include <algorithm>
#include <limits>

#include "cpu_reference/sampling/triangle_soa.h"
#include "kernels/bvh/closest_triangle_bvh.h"

namespace sdf {

/// Triangles per block: the block's 24 arrays (24 KiB in float) stay in the L1 cache while
/// every point of the tile runs over them.
constexpr int kTriangleBlock = 256;
/// Points that share one pass over the triangle blocks.
constexpr int kPointTile = 16;

/// For each of the `count` points (at most kPointTile), the index of the triangle with the
/// smallest squared distance (lowest index on ties) and that squared distance. `near[p]`
/// (PlainNear, or CertifiedNear for the certified float search) receives every triangle
/// within point p's radius; a block is looked at again only when its minimum is within it.
template <typename T, typename Near>
void nearest_triangles_vectorized(const TriangleSoA<T>& soa, int count, const T* px, const T* py, const T* pz,
                                  int* best_index, T* best_q, Near* near) {
    const T* __restrict f[TriangleSoA<T>::kFields];
    for (int k = 0; k < TriangleSoA<T>::kFields; ++k) f[k] = soa.field(k);
    for (int p = 0; p < count; ++p) {
        best_index[p] = -1;
        best_q[p] = std::numeric_limits<T>::infinity();
    }
    alignas(64) T q[kTriangleBlock];
    alignas(64) T ranked[kTriangleBlock];  ///< q less sliver_excess(): what candidates are ranked by
    constexpr bool kDouble = sizeof(T) == sizeof(double);  // float has no interior slivers
    const int n = soa.size();
    const std::vector<int>& slivers = soa.interior_slivers();
    auto sliver = slivers.begin();
    for (int start = 0; start < n; start += kTriangleBlock) {
        const int len = std::min(kTriangleBlock, n - start);
        // This block's slivers (double only), re-evaluated after the vector loop (squared_distance()).
        const auto slivers_begin = sliver;
        if constexpr (kDouble)
            while (sliver != slivers.end() && *sliver < start + len) ++sliver;
        const auto slivers_end = sliver;
        for (int p = 0; p < count; ++p) {
            const T x = px[p], y = py[p], z = pz[p];
            T block_min = std::numeric_limits<T>::infinity(), block_ranked = block_min;
#pragma omp simd reduction(min : block_min, block_ranked)
            for (int i = 0; i < len; ++i) {
                const int j = start + i;
                const PackedTriangle<T> t{f[0][j],  f[1][j],  f[2][j],  f[3][j],  f[4][j],  f[5][j],
                                          f[6][j],  f[7][j],  f[8][j],  f[9][j],  f[10][j], f[11][j],
                                          f[12][j], f[13][j], f[14][j], f[15][j], f[16][j], f[17][j],
                                          f[18][j], f[19][j], f[20][j], f[21][j], f[22][j], f[23][j]};
                const T d = branch_free_squared_distance(t, x, y, z);
                q[i] = d;
                block_min = d < block_min ? d : block_min;
                if constexpr (Near::kKeeps) {
                    const T r = d - sliver_excess(t);
                    ranked[i] = r;
                    block_ranked = r < block_ranked ? r : block_ranked;
                }
            }
            if constexpr (kDouble) {
                if (slivers_begin != slivers_end) {
                    for (auto k = slivers_begin; k != slivers_end; ++k)
                        q[*k - start] = sliver_squared_distance(soa[*k], x, y, z);
                    block_min = std::numeric_limits<T>::infinity();
                    for (int i = 0; i < len; ++i) block_min = q[i] < block_min ? q[i] : block_min;
                }
            }
            if (block_min < best_q[p]) {
                int i = 0;
                while (q[i] != block_min) ++i;
                best_q[p] = block_min;
                best_index[p] = start + i;
            }
            if constexpr (Near::kKeeps) {
                const T radius = near[p].radius(best_q[p]);  // shrinks block by block: earlier blocks kept more
                if (block_ranked <= radius)
                    for (int i = 0; i < len; ++i)
                        if (ranked[i] <= radius) near[p].offer(start + i, ranked[i]);
            }
        }
    }
}

template <typename T>
void nearest_triangles_vectorized(const TriangleSoA<T>& soa, int count, const T* px, const T* py, const T* pz,
                                  int* best_index, T* best_q) {
    PlainNear plain[kPointTile];
    nearest_triangles_vectorized(soa, count, px, py, pz, best_index, best_q, plain);
}

}  // namespace sdf
