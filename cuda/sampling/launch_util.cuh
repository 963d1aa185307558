/// @file launch_util.cuh
/// @brief What the CUDA samplers' launchers share, as NanoVDB's util/cuda/Util.h is for its
/// tools: the grid size of a one-thread-per-item launch, and the results of one piece of
/// points on the device and their download to the host. The brute-force sampler
/// (cuda_sampler.cu) and the BVH sampler (bvh_sampler.cu) both finalize into these buffers
/// (finalize_kernel.cuh) and scatter the download (core/sampling/sampler_results.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cuda/util/cuda_check.h"
#include "cuda/util/device_buffer.h"
#include "cuda/sampling/finalize_kernel.cuh"

namespace sdf::cuda {

/// Blocks of `threads` threads that cover `n` items, one thread each. Callers size their
/// pieces from GPU memory, which keeps n / threads far below 2^31 (the grid's x limit).
inline int blocks_for(int64_t n, int threads) { return int((n + threads - 1) / threads); }

/// One piece's finalized results on the host, in the piece's point order.
struct HostPieceResults {
    std::vector<double> distance;
    std::vector<Vec3d> gradient;
    std::vector<int> triangle;
    std::vector<int64_t> output_index;  ///< where each point goes in the field; -1: padding or discarded
};

/// One piece's finalized results on the device, written through outputs() by the finalize
/// kernels and brought to the host by download().
struct DevicePieceResults {
    DeviceBuffer<double> distance;
    DeviceBuffer<Vec3d> gradient;
    DeviceBuffer<int> triangle;
    DeviceBuffer<int64_t> output_index;

    explicit DevicePieceResults(int64_t n)
        : distance{size_t(n)}, gradient{size_t(n)}, triangle{size_t(n)}, output_index{size_t(n)} {}

    /// Device bytes per point, for the samplers' memory plans.
    static constexpr size_t bytes_per_point() { return 4 * sizeof(double) + sizeof(int) + sizeof(int64_t); }

    PieceOutputs outputs() const { return {distance.get(), gradient.get(), triangle.get(), output_index.get()}; }

    /// The first n results, copied on the default stream and waited for.
    HostPieceResults download(int64_t n) const {
        HostPieceResults h{std::vector<double>(size_t(n)), std::vector<Vec3d>(size_t(n)), std::vector<int>(size_t(n)),
                           std::vector<int64_t>(size_t(n))};
        distance.download(h.distance.data(), size_t(n));
        gradient.download(h.gradient.data(), size_t(n));
        triangle.download(h.triangle.data(), size_t(n));
        output_index.download(h.output_index.data(), size_t(n));
        CUDA_CHECK(cudaStreamSynchronize(0));
        return h;
    }
};

}  // namespace sdf::cuda
