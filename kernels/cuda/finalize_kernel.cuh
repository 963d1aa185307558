/// @file finalize_kernel.cuh
/// @brief After the nearest-triangle search: Eberly's closest point on the winning triangle,
/// the pseudonormal sign and the exact gradient (thesis sections 3.3-3.4), on the GPU, with
/// the same signed_distance_to_triangle() the CPU reference calls.
#pragma once

#include "kernels/cuda/point_pieces.h"
#include "kernels/distance/signed_distance.h"

namespace sdf::cuda {

/// Per-piece results, downloaded and scattered into the field by the host.
template <typename T>
struct PieceOutputs {
    T* distance;
    Vec3<T>* gradient;
    int* triangle;
    int64_t* output_index;  ///< -1: padding or discarded
};

template <typename T, typename Piece>
__global__ void finalize_samples(MeshView<T> mesh, Piece piece, const int* nearest, PieceOutputs<T> out) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= piece.size()) return;
    const int64_t o = piece.block_local(i) < 0 ? -1 : piece.output_index(i);
    out.output_index[i] = o;
    if (o < 0) return;
    const SignedDistanceSample<T> s = signed_distance_to_triangle(mesh, Vec3<T>(piece.position(i)), nearest[i]);
    out.distance[i] = s.distance;
    out.gradient[i] = s.gradient;
    out.triangle[i] = s.triangle;
}

}  // namespace sdf::cuda
