/// @file device_query.h
/// @brief Point queries whose points and results stay in GPU memory (a PyTorch, CuPy or JAX
/// tensor's own buffer): the points are read where they are, with their dtype and strides,
/// and the results are written where the caller asks, in input order, so that a CUDA input
/// never touches the host. Only samplers that run on a GPU answer them (the CUDA BVH
/// sampler); the numbers equal Sampler::query() on the same points bit for bit.
#pragma once

#include <cstdint>

namespace sdf {

/// N points in device memory: point i is (xyz[i*row], xyz[i*row + col], xyz[i*row + 2*col]),
/// strides in elements of float (float32) or double.
struct DevicePoints {
    const void* xyz = nullptr;
    bool float32 = false;
    int64_t count = 0;
    int64_t row_stride = 3;
    int64_t column_stride = 1;
    int device = 0;        ///< the CUDA device holding them
    void* stream = nullptr;  ///< the caller's cudaStream_t: ordered after the work already on it
};

/// Where the results go, in device memory, in input order; a null pointer skips that output.
struct DeviceQueryResults {
    double* distance = nullptr;   ///< N
    double* gradient = nullptr;   ///< N x 3, row-major
    int32_t* triangle = nullptr;  ///< N, in the mesh file's face order
};

}  // namespace sdf
