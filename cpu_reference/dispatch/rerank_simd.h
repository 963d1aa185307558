/// @file rerank_simd.h
/// @brief rerank_in_double() (search_certificate.h) with the candidates' double squared
/// distances computed as one vector loop: the same winner, bit for bit.
///
/// rerank_in_double() evaluates Q_d of the float winner, then of each candidate within the
/// radius in order, keeping the least (Q_d, triangle index). Here the same triangles, in the
/// same order (the winner first), are copied into structure-of-arrays form, their Q_d computed
/// by the same squared_distance() in an `omp simd` loop (the same operations per lane, no
/// contraction: the same bits; its branch-free form there, the few slivers after), and the
/// least is then chosen by the same comparisons in the same order. The lattices' points re-rank several candidates almost everywhere (the
/// triangles around a nearest vertex or edge tie), so this loop is hot.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "kernels/distance/search_certificate.h"

namespace sdf {

/// Triangles whose Q_d one vector loop computes.
constexpr int kRerankChunk = 16;

/// Q_d at (px, py, pz) of the `n` (<= kRerankChunk) BVH slots `slots` into `q`.
inline void double_squared_distances(const PackedTriangle<double>* packed, const int32_t* slots, int n, double px,
                                     double py, double pz, double* q) {
    constexpr int kFields = int(sizeof(PackedTriangle<double>) / sizeof(double));
    static_assert(kFields == 24 && sizeof(PackedTriangle<double>) == kFields * sizeof(double),
                  "PackedTriangle<double>: 24 doubles, no padding (the copy below relies on it)");
    static_assert(offsetof(PackedTriangle<double>, sb) == 13 * sizeof(double) &&
                      offsetof(PackedTriangle<double>, ta) == 14 * sizeof(double),
                  "fields 13 and 14 are sb and ta (the sliver test below)");
    alignas(64) double f[kFields][kRerankChunk];
    for (int i = 0; i < n; ++i) {
        double row[kFields];
        std::memcpy(row, &packed[slots[i]], sizeof(row));
        for (int k = 0; k < kFields; ++k) f[k][i] = row[k];
    }
#pragma omp simd
    for (int i = 0; i < n; ++i) {
        const PackedTriangle<double> t{f[0][i],  f[1][i],  f[2][i],  f[3][i],  f[4][i],  f[5][i],  f[6][i],  f[7][i],
                                       f[8][i],  f[9][i],  f[10][i], f[11][i], f[12][i], f[13][i], f[14][i], f[15][i],
                                       f[16][i], f[17][i], f[18][i], f[19][i], f[20][i], f[21][i], f[22][i], f[23][i]};
        q[i] = branch_free_squared_distance(t, px, py, pz);
    }
    // squared_distance() of the slivers (sb NaN, ta not: is_interior_sliver), out of the vector loop.
    for (int i = 0; i < n; ++i)
        if (f[13][i] != f[13][i] && f[14][i] == f[14][i]) q[i] = sliver_squared_distance(packed[slots[i]], px, py, pz);
}

/// rerank_in_double() for BVH slots or triangle indices (`index_of`), its result bit for bit.
template <typename T, typename IndexOf>
Rerank rerank_in_double_simd(const PackedTriangle<double>* packed_double, IndexOf index_of, double px, double py,
                             double pz, int32_t winner, T radius, const int32_t* slot, const T* q, int count,
                             T dropped) {
    Rerank r;
    if (dropped <= radius) {
        r.overflow = true;
        return r;
    }
    r.slot = winner;
    // The triangles rerank_in_double() evaluates, in its order: the winner, then the others within.
    int32_t chunk[kRerankChunk];
    int n = 0;
    chunk[n++] = winner;
    double best = 0;
    int32_t best_index = index_of(winner);
    bool first_chunk = true;
    auto evaluate = [&]() {
        double d[kRerankChunk];
        double_squared_distances(packed_double, chunk, n, px, py, pz, d);
        int i = 0;
        if (first_chunk) {  // chunk[0] is the winner
            best = d[0];
            i = 1;
            first_chunk = false;
        }
        for (; i < n; ++i) {
            const int32_t index = index_of(chunk[i]);
            if (d[i] < best || (d[i] == best && index < best_index)) {
                best = d[i];
                best_index = index;
                r.slot = chunk[i];
            }
        }
        n = 0;
    };
    for (int i = 0; i < count; ++i) {
        if (slot[i] == winner || !(q[i] <= radius)) continue;
        r.reranked = true;
        chunk[n++] = slot[i];
        if (n == kRerankChunk) evaluate();
    }
    if (r.reranked && n > 0) evaluate();
    return r;
}

}  // namespace sdf
