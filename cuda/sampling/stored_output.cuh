/// @file stored_output.cuh
/// @brief A slab's results in the bytes of the field file (core/sampling/stored_slab.h),
/// made on the device: after each piece's finalize, store_piece() writes every sample to its
/// place in the slab's compact order, in the file's float type, with the triangle renumbered
/// to the mesh file's face order; the slab then comes to the host in one copy per channel
/// into pinned memory, which the writer hands to pwrite() as it is. The host does no scatter
/// and no conversion, so the time it spends per slab is the copy (PCIe) and the disk.
#pragma once

#include <cuda_runtime.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "core/sampling/sampler.h"
#include "core/sampling/stored_slab.h"
#include "cuda/util/cuda_check.h"
#include "cuda/util/device_buffer.h"
#include "cuda/sampling/finalize_kernel.cuh"

namespace sdf::cuda {

/// Device pointers of one slab's stored channels (null: channel not stored).
template <typename F>
struct StoredChannels {
    F* distance;
    F* gradient;
    int32_t* triangle;
    const int32_t* source_triangle;          ///< prepared -> mesh file face order
    unsigned long long* outside_band_count;  ///< points flagged kOutsideBandTriangle
};

/// Moves piece results [0, n) to their slab places (output_index; < 0: none) as type F.
template <typename F>
__global__ void store_piece(PieceOutputs piece, int64_t n, StoredChannels<F> out) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const int64_t o = piece.output_index[i];
    if (o < 0) return;
    out.distance[o] = F(piece.distance[i]);
    if (out.gradient) {
        const Vec3d g = piece.gradient[i];
        out.gradient[3 * o] = F(g.x);
        out.gradient[3 * o + 1] = F(g.y);
        out.gradient[3 * o + 2] = F(g.z);
    }
    const int t = piece.triangle[i];
    if (out.triangle) out.triangle[o] = t < 0 ? t : out.source_triangle[t];
    if (t == kOutsideBandTriangle) atomicAdd(out.outside_band_count, 1ull);
}

/// The device and pinned host buffers of stored slabs. Host buffers are handed out as shared
/// pointers and taken again only when nobody else holds them (the writer of an earlier slab
/// may still be copying from one), so two of them alternate while slabs stream to disk.
class StoredSlabBuffers {
public:
    /// Device channel pointers for a slab of `points` in `layout` (zeroed outside-band count).
    template <typename F>
    StoredChannels<F> device_channels(int64_t points, const StoredLayout& layout, const int32_t* source_triangle) {
        const size_t n = size_t(points);
        if (device_.size() < n * layout.bytes_per_point()) device_.allocate(n * layout.bytes_per_point());
        if (count_.size() == 0) count_.allocate(1);
        CUDA_CHECK(cudaMemsetAsync(count_.get(), 0, sizeof(unsigned long long)));
        char* base = device_.get();
        F* distance = reinterpret_cast<F*>(base);
        F* gradient = layout.gradient ? distance + n : nullptr;
        int32_t* triangle = layout.closest_triangle ? reinterpret_cast<int32_t*>(base + n * layout.value_bytes() * (layout.gradient ? 4 : 1))
                                                    : nullptr;
        return {distance, gradient, triangle, source_triangle, count_.get()};
    }

    /// Copies the slab's channels into free pinned memory and fills `slab`'s pointers and band count.
    void download(int64_t points, const StoredLayout& layout, StoredSlab& slab) {
        const size_t bytes = size_t(points) * layout.bytes_per_point();
        std::shared_ptr<PinnedBytes> host = free_host(bytes);
        CUDA_CHECK(cudaMemcpyAsync(host->get(), device_.get(), bytes, cudaMemcpyDeviceToHost));
        unsigned long long outside = 0;
        CUDA_CHECK(cudaMemcpyAsync(&outside, count_.get(), sizeof outside, cudaMemcpyDeviceToHost));
        CUDA_CHECK(cudaStreamSynchronize(0));
        const size_t n = size_t(points), values = n * layout.value_bytes();
        slab.points = points;
        slab.distance = host->get();
        slab.gradient = layout.gradient ? host->get() + values : nullptr;
        slab.closest_triangle = layout.closest_triangle ? host->get() + values * (layout.gradient ? 4 : 1) : nullptr;
        slab.band.outside = int64_t(outside);
        slab.band.in_band = points - int64_t(outside);
        slab.storage = host;
    }

private:
    std::shared_ptr<PinnedBytes> free_host(size_t bytes) {
        for (std::shared_ptr<PinnedBytes>& h : host_)
            if (h.use_count() == 1) {
                if (h->size() < bytes) h = std::make_shared<PinnedBytes>(bytes);
                return h;
            }
        host_.push_back(std::make_shared<PinnedBytes>(bytes));
        return host_.back();
    }

    DeviceBuffer<char> device_;
    DeviceBuffer<unsigned long long> count_;
    std::vector<std::shared_ptr<PinnedBytes>> host_;
};

}  // namespace sdf::cuda
