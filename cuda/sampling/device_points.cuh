/// @file device_points.cuh
/// @brief The kernels of queries whose points and results stay on the device
/// (core/sampling/device_query.h): the caller's points, of either float type and any
/// strides, read into the search's double points while checking the search's range, and
/// the results written back to the caller's arrays in input order.
#pragma once

#include <cstdint>

#include "core/sampling/device_query.h"
#include "cuda/sampling/finalize_kernel.cuh"

namespace sdf::cuda {

/// points[i] = the caller's point i as doubles; `first_bad[0]` takes (atomicMin) the smallest
/// index of a point that is not finite or has a coordinate beyond `limit` (the search's range),
/// `first_bad[1]` (atomicMax on the bits: non-negative doubles order as their bit patterns)
/// the largest |coordinate| of the points in range, which the certified search's bound takes.
template <typename F>
__global__ void read_device_points(const F* xyz, int64_t n, int64_t row, int64_t col, double limit, Vec3d* points,
                                   unsigned long long* first_bad) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const F* p = xyz + i * row;
    const Vec3d q{double(p[0]), double(p[col]), double(p[2 * col])};
    points[i] = q;
    // !(|x| <= limit) is true for NaN too.
    const double m = fmax(fabs(q.x), fmax(fabs(q.y), fabs(q.z)));
    if (!(fabs(q.x) <= limit) || !(fabs(q.y) <= limit) || !(fabs(q.z) <= limit)) atomicMin(first_bad, (unsigned long long)i);
    else {
        const unsigned long long bits = (unsigned long long)__double_as_longlong(m);
        if (bits > *(volatile unsigned long long*)(first_bad + 1)) atomicMax(first_bad + 1, bits);  // few atomics
    }
}

/// Which sorted result goes to which input position, for the kernels that move point-list
/// results into input order: thread t takes sorted result t to its input position
/// output_index[t] (a scatter: any piece of a list), or, where `rank` (input position ->
/// sorted position: a list in one piece of fewer than 2^31 points) is given, input position
/// t gathers sorted result rank[t]. The gather's writes coalesce where the scatter's land
/// one point apart in three arrays: 16.8M points to the caller's columns took 4.6 ms
/// scattered on an H200 (docs/gpu-notes.md).
struct ResultOrder {
    const int32_t* rank = nullptr;

    /// Thread t's sorted result `i` and input position `o`; false: none (padding).
    __device__ SDF_INLINE bool of(const PieceOutputs& piece, int64_t t, int64_t& i, int64_t& o) const {
        if (rank != nullptr) {
            o = t;
            i = rank[t];
            return true;
        }
        i = t;
        o = piece.output_index[t];
        return o >= 0;
    }
};

/// Moves point-list results [0, n) to the caller's arrays at their input positions,
/// triangles in the mesh file's face order.
__global__ inline void store_point_columns(PieceOutputs piece, int64_t n, ResultOrder order, const int32_t* source_triangle,
                                           DeviceQueryResults out) {
    const int64_t t = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    int64_t i = 0, o = 0;
    if (t >= n || !order.of(piece, t, i, o)) return;
    if (out.distance) out.distance[o] = piece.distance[i];
    if (out.gradient) {
        const Vec3d g = piece.gradient[i];
        out.gradient[3 * o] = g.x;
        out.gradient[3 * o + 1] = g.y;
        out.gradient[3 * o + 2] = g.z;
    }
    if (out.triangle) {
        const int tri = piece.triangle[i];
        out.triangle[o] = tri < 0 ? tri : source_triangle[tri];
    }
}

/// Moves point-list results [0, n) to their input positions as PointSample records,
/// triangles in the mesh file's face order: the host then copies them as they are.
template <typename Sample>
__global__ void store_point_samples(PieceOutputs piece, int64_t n, ResultOrder order, const int32_t* source_triangle,
                                    Sample* out) {
    const int64_t t = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    int64_t i = 0, o = 0;
    if (t >= n || !order.of(piece, t, i, o)) return;
    const int tri = piece.triangle[i];
    out[o] = Sample{piece.distance[i], piece.gradient[i], tri < 0 ? tri : source_triangle[tri]};
}

}  // namespace sdf::cuda
