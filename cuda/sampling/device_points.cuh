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

/// Moves point-list results [0, n) to the caller's arrays at their input positions
/// (output_index), triangles in the mesh file's face order.
__global__ inline void store_point_columns(PieceOutputs piece, int64_t n, const int32_t* source_triangle, DeviceQueryResults out) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const int64_t o = piece.output_index[i];
    if (o < 0) return;
    if (out.distance) out.distance[o] = piece.distance[i];
    if (out.gradient) {
        const Vec3d g = piece.gradient[i];
        out.gradient[3 * o] = g.x;
        out.gradient[3 * o + 1] = g.y;
        out.gradient[3 * o + 2] = g.z;
    }
    if (out.triangle) {
        const int t = piece.triangle[i];
        out.triangle[o] = t < 0 ? t : source_triangle[t];
    }
}

}  // namespace sdf::cuda
