/// @file thesis_kernel.cuh
/// @brief The brute-force kernel as thesis section 3.3 describes it.
///
/// One thread per lattice point; the lattice is cut into 32x32x32 regions of 32 blocks x 256
/// threads; triangles arrive in chunks through constant memory and are staged in shared
/// memory; Eberly's algorithm runs on every pair; the running minimum (squared distance,
/// triangle, s, t) lives in global memory across launches, so each launch continues where
/// the previous chunk stopped. Sign and gradient are computed afterwards from (s, t).
#pragma once

#include "cuda/sampling/finalize_kernel.cuh"
#include "cuda/sampling/point_pieces.h"
#include "kernels/distance/closest_point_on_triangle.h"
#include "kernels/distance/signed_distance.h"

namespace sdf::cuda {

constexpr int kThesisThreads = 256;       ///< threads per block (thesis: 256)
constexpr int kThesisBlocksPerRegion = 32;  ///< blocks per 32^3 region (thesis: 32)
constexpr int kThesisConstantBytes = 60 * 1024;  ///< constant memory for one triangle chunk
constexpr int kThesisStage = 64;          ///< triangles staged in shared memory at a time

/// One chunk of triangles as 9 scalars each (V0, V1, V2), reinterpreted as float or double.
/// Defined here: include this header from exactly one translation unit (cuda_sampler.cu).
__constant__ unsigned char c_thesis_chunk[kThesisConstantBytes];

template <typename T>
constexpr int thesis_chunk_triangles() { return kThesisConstantBytes / int(9 * sizeof(T)); }

/// The running minimum of one point, kept in global memory between launches.
template <typename T>
struct ThesisMinima {
    T* distance_squared;
    int* triangle;  ///< index into the prepared mesh, -1 before the first chunk
    T* s;
    T* t;
    int* feature;   ///< TriangleFeature of the closest point (from Eberly's region)
};

/// `Piece` is a GridRegionPiece for lattices (the thesis's layout) or a PointListPiece for
/// arbitrary query points.
template <typename T, typename Piece>
__global__ void __launch_bounds__(kThesisThreads)
    nearest_triangle_thesis(Piece piece, int chunk_first_triangle, int chunk_count, ThesisMinima<T> minima) {
    __shared__ T staged[kThesisStage * 9];
    const int64_t i = int64_t(blockIdx.x) * kThesisThreads + threadIdx.x;
    // Point lists are not padded to whole blocks: idle threads still help stage triangles.
    const bool active = i < piece.size();
    const int64_t me = active ? i : 0;
    const Vec3<T> p(piece.position(me));

    // Continue from the minimum the previous launches left in global memory.
    T best = minima.distance_squared[me], best_s = minima.s[me], best_t = minima.t[me];
    int best_tri = minima.triangle[me], best_feature = minima.feature[me];

    const T* chunk = reinterpret_cast<const T*>(c_thesis_chunk);
    for (int base = 0; base < chunk_count; base += kThesisStage) {
        const int count = min(kThesisStage, chunk_count - base);
        __syncthreads();
        for (int w = threadIdx.x; w < count * 9; w += kThesisThreads) staged[w] = chunk[base * 9 + w];
        __syncthreads();
        for (int j = 0; j < count; ++j) {
            const T* v = staged + 9 * j;
            const TriangleClosestPoint<T> r = closest_point_on_triangle(p, Vec3<T>(v[0], v[1], v[2]),
                                                                        Vec3<T>(v[3], v[4], v[5]), Vec3<T>(v[6], v[7], v[8]));
            if (r.distance_squared < best) {
                best = r.distance_squared;
                best_tri = chunk_first_triangle + base + j;
                best_s = r.s;
                best_t = r.t;
                best_feature = int(r.feature);
            }
        }
    }
    if (!active) return;
    minima.distance_squared[i] = best;
    minima.triangle[i] = best_tri;
    minima.s[i] = best_s;
    minima.t[i] = best_t;
    minima.feature[i] = best_feature;
}

template <typename T>
__global__ void fill_thesis_minima(int64_t n, ThesisMinima<T> m) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    m.distance_squared[i] = T(INFINITY);
    m.triangle[i] = -1;
    m.s[i] = T(0);
    m.t[i] = T(0);
    m.feature[i] = 0;
}

/// "Sign computations, gradient computations" of thesis Figure 3-2, after the search. The
/// kernel returned (s, t) in float as the thesis's did; like every sampler here, the final
/// closest point, feature, sign and gradient are re-evaluated with Eberly's algorithm in
/// double on the winning triangle at the exact lattice position, so the thesis kernel's
/// fields equal the CPU reference's except where the float search broke a near-tie.
/// `Winding`: as finalize_samples (finalize_kernel.cuh).
template <typename T, bool Winding, typename Piece>
__global__ void finalize_thesis_samples(MeshView<double> mesh, Piece piece, ThesisMinima<T> minima, WindingSignView sign,
                                        double band_width, PieceOutputs out) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= piece.size()) return;
    const int64_t o = piece.block_local(i) < 0 ? -1 : piece.output_index(i);
    out.output_index[i] = o;
    if (o < 0) return;
    const Vec3d p = piece.position(i);
    SignedDistanceSample<double> s = signed_distance_to_triangle(mesh, p, minima.triangle[i]);
    if constexpr (Winding) s = apply_winding_sign(sign, s, p);
    store_sample(out, i, s, band_width);
}

}  // namespace sdf::cuda
