/// @file finalize_kernel.cuh
/// @brief After the nearest-triangle search: Eberly's closest point on the winning triangle,
/// the pseudonormal sign and the exact gradient (thesis sections 3.3-3.4), on the GPU, with
/// the same signed_distance_to_triangle() the CPU reference calls. As on the CPU, this step
/// runs in double at the exact lattice position whatever the search precision: it costs one
/// triangle per point and makes float fields exact to double rounding. In sign mode
/// "winding" the sample then takes the fast winding number's side (winding_sign_kernel.cuh).
#pragma once

#include "cuda/point_pieces.h"
#include "cuda/winding_sign_kernel.cuh"
#include "kernels/distance/signed_distance.h"

namespace sdf::cuda {

/// Per-piece results, downloaded and scattered into the field by the host.
struct PieceOutputs {
    double* distance;
    Vec3d* gradient;
    int* triangle;
    int64_t* output_index;  ///< -1: padding or discarded
};

/// With `Winding` the sample then takes the winding number's side; without it the kernel has
/// no winding code at all (pseudonormal mode: the kernel as it was before sign modes).
template <typename Piece, bool Winding>
__global__ void finalize_samples(MeshView<double> mesh, Piece piece, const int* nearest, WindingSignView sign, PieceOutputs out) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= piece.size()) return;
    const int64_t o = piece.block_local(i) < 0 ? -1 : piece.output_index(i);
    out.output_index[i] = o;
    if (o < 0) return;
    const Vec3d p = piece.position(i);
    SignedDistanceSample<double> s = signed_distance_to_triangle(mesh, p, nearest[i]);
    if constexpr (Winding) s = apply_winding_sign(sign, s, p);
    out.distance[i] = s.distance;
    out.gradient[i] = s.gradient;
    out.triangle[i] = s.triangle;
}

/// Launches finalize_samples with or without the winding sign, as `sign` says.
template <typename Piece>
void launch_finalize_samples(int blocks, int threads, MeshView<double> mesh, const Piece& piece, const int* nearest,
                             const WindingSignView& sign, PieceOutputs out) {
    if (sign.enabled()) finalize_samples<Piece, true><<<blocks, threads>>>(mesh, piece, nearest, sign, out);
    else finalize_samples<Piece, false><<<blocks, threads>>>(mesh, piece, nearest, sign, out);
}

}  // namespace sdf::cuda
