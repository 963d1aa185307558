/// @file host_query.h
/// @brief Point queries on the caller's host arrays: points read where they are (float32 or
/// float64, any strides, e.g. a NumPy array's buffer) and results written into the caller's
/// columns in input order, so that a front end allocates its outputs once and converts
/// nothing. Samplers that run on a GPU stream both through pinned buffers; the CPU BVH
/// sampler reads the points and writes the columns in place (point_count/point_at below);
/// every other sampler gathers the points and answers with Sampler::query(). The numbers
/// equal query()'s on the same points bit for bit.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "kernels/core/vec3.h"

namespace sdf {

struct PointSample;

/// N points in host memory: point i is (xyz[i*row], xyz[i*row + col], xyz[i*row + 2*col]),
/// strides in elements of float (float32) or double.
struct HostPoints {
    const void* xyz = nullptr;
    bool float32 = false;
    int64_t count = 0;
    int64_t row_stride = 3;
    int64_t column_stride = 1;

    /// Point i in double (float32 widens exactly).
    Vec3d operator[](int64_t i) const {
        const int64_t a = i * row_stride;
        if (float32) {
            const float* f = static_cast<const float*>(xyz);
            return {f[a], f[a + column_stride], f[a + 2 * column_stride]};
        }
        const double* d = static_cast<const double*>(xyz);
        return {d[a], d[a + column_stride], d[a + 2 * column_stride]};
    }
    /// Rows of three consecutive values, one after the other: one block of bytes.
    bool contiguous() const { return row_stride == 3 && column_stride == 1; }
    size_t bytes() const { return size_t(count) * 3 * (float32 ? sizeof(float) : sizeof(double)); }
};

/// A point list as the CPU queries read it, whether the caller's arrays or a vector: how many
/// points and point i (in double), so one search serves both.
inline int64_t point_count(const std::vector<Vec3d>& points) { return int64_t(points.size()); }
inline Vec3d point_at(const std::vector<Vec3d>& points, int64_t i) { return points[size_t(i)]; }
inline int64_t point_count(const HostPoints& points) { return points.count; }
inline Vec3d point_at(const HostPoints& points, int64_t i) { return points[i]; }

/// Where a host query's results go, in input order; a null pointer skips that output.
struct HostQueryResults {
    double* distance = nullptr;   ///< N
    double* gradient = nullptr;   ///< N x 3, row-major
    int32_t* triangle = nullptr;  ///< N, in the mesh file's face order
};

/// Writes result `s` of point i into the columns `r` asks for.
void store_result(const HostQueryResults& r, int64_t i, const PointSample& s);

/// Throws std::invalid_argument naming `argument` and the first row (0-based, as NumPy
/// counts) that is not three finite numbers. Checked on `threads` threads (0: all).
void require_finite_points(const HostPoints& points, const std::string& argument, int threads);

/// The points as doubles (checked as require_finite_points does).
std::vector<Vec3d> gather_points(const HostPoints& points, const std::string& argument, int threads);

/// Writes samples[i] into the columns of `results` (row i), on `threads` threads.
void scatter_samples(const std::vector<PointSample>& samples, const HostQueryResults& results, int threads);

}  // namespace sdf
