/// @file bvh_bound_sampler.cuh
/// @brief The CUDA BVH sampler bound to its mesh (cuda/bvh/bvh_sampler.h), for its four
/// translation units: the tree made at binding (bvh_device_tree.cu), the lattice path
/// (bvh_sampler.cu), the point-query path (bvh_point_query.cu) and the sparse band's blocks
/// (bvh_band_blocks.cu). Its device scratch
/// (candidate counters, pinned buffers, a stored slab's channels, the certificate's
/// counters) is kept between calls, so calls are serialised inside.
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "core/sampling/backend_sampler.h"
#include "cuda/bvh/bvh_device_tree.cuh"
#include "cuda/bvh/bvh_kernel.cuh"
#include "cuda/bvh/bvh_sampler.h"
#include "cuda/bvh/bvh_warp_kernel.cuh"
#include "cuda/sampling/finalize_kernel.cuh"
#include "cuda/sampling/launch_util.cuh"
#include "cuda/util/staged_copy.h"
#include "cuda/sampling/stored_output.cuh"

namespace sdf::cuda {

/// Per-piece results on the device: the search's nearest triangle, then the finalized samples.
struct PieceResults {
    DeviceBuffer<int> nearest;
    DevicePieceResults samples;
    static size_t bytes_per_point() { return sizeof(int) + DevicePieceResults::bytes_per_point(); }

    explicit PieceResults(int64_t n) : nearest{size_t(n)}, samples(n) {}
    PieceOutputs outputs() const { return samples.outputs(); }
    HostPieceResults download(int64_t n) const { return samples.download(n); }
};
class BoundCudaBvh final : public BackendSampler {
public:
    /// Builds the tree where options.bvh_build says (bvh_device_tree.cu) and uploads what
    /// the searches, the certificate and the winding sign read.
    BoundCudaBvh(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, BvhGpuKernel kernel);

    std::optional<StoredSlab> sample_slab_stored(const Lattice& lattice, const LatticeSlab& slab,
                                                 const StoredLayout& layout) const override;
    bool query_device(const DevicePoints& points, const DeviceQueryResults& results,
                      SamplingTimings* timings = nullptr) const override;
    /// Host arrays in and out (a NumPy array's buffer): the caller's bytes go to the device as
    /// they are (float32 stays float32 on the bus) through pinned buffers, the search is
    /// query_device()'s, and the result columns come back through pinned buffers straight into
    /// the caller's arrays: no conversion, no host scatter, the copies overlapped.
    void query_host(const HostPoints& points, const HostQueryResults& results,
                    SamplingTimings* timings = nullptr) const override;

private:
    SampledField sample_blocks(SlabRun& run) const override;
    std::vector<PointSample> query_points(const std::vector<Vec3d>& points, SamplingTimings& timings,
                                          CertificateCounters& certificate) const override;
    /// The sparse band's active blocks in device memory (bvh_band_blocks.cu; warp and candidates).
    BandBlockKernel band_block_kernel(double width) const override;

    // ---- the tree (bvh_device_tree.cu) ------------------------------------------------
    template <typename T>
    void upload_host_tree();
    template <typename T>
    bool build_on_device();
    /// The tree of the search's precision T (the other is null).
    template <typename T>
    const DeviceBvh<T>& tree() const {
        if constexpr (std::is_same_v<T, float>) return *tree_float_;
        else return *tree_double_;
    }

    // ---- lattices (bvh_sampler.cu) ------------------------------------------------------
    int layers_per_slab(const GridBlock& block) const;
    template <typename T>
    BandSearch band_search(const DeviceBvh<T>& dev) const;
    template <typename T>
    void launch_slab(const DeviceBvh<T>& dev, const GridRangePiece& piece, const SlabGeometry& slab,
                     const StreamedCertify& cert, int* nearest) const;
    template <typename T, typename Sink>
    void run_slab(const DeviceBvh<T>& dev, const Lattice& lattice, const GridBlock& block, int z0, int nz,
                  EventTimer& compute, Sink sink) const;
    template <typename T, typename Sink>
    int64_t run_blocks(const DeviceBvh<T>& dev, SlabRun& run, EventTimer& compute, Sink sink) const;
    template <typename T, typename F>
    int64_t store_blocks(const DeviceBvh<T>& dev, SlabRun& run, const StoredChannels<F>& out, EventTimer& compute) const;
    template <typename T>
    SampledField sample_as(SlabRun& run) const;
    template <typename T>
    StoredSlab sample_stored_as(SlabRun& run, const StoredLayout& layout) const;
    /// The run's timings and details (plan, BVH, device, candidates) and certificate.
    template <typename T>
    void record_run(SlabRun& run, const DeviceBvh<T>& dev, const EventTimer& upload, const EventTimer& compute,
                    const EventTimer& download, int64_t pieces) const;

    // ---- sparse band blocks (bvh_band_blocks.cu) ------------------------------------------
    template <typename T>
    void band_blocks_as(SparseBandField& band, size_t first, size_t last, double width) const;

    // ---- point lists (bvh_point_query.cu) -----------------------------------------------
    template <typename T>
    std::vector<PointSample> query_as(const std::vector<Vec3d>& points, SamplingTimings& timings,
                                      CertificateCounters& certificate) const;
    template <typename T>
    void query_device_as(const DevicePoints& points, const DeviceQueryResults& results, SamplingTimings& timings) const;
    void query_device_locked(const DevicePoints& points, const DeviceQueryResults& results, SamplingTimings& timings) const;
    double read_points(const DevicePoints& points, Vec3d* out) const;
    template <typename T, typename Store>
    void search_points(const DeviceBvh<T>& dev, const Vec3d* device_points, int64_t n, double coordinate,
                       EventTimer& compute, CertificateCounters& certificate, Store store) const;

    /// The warp searches' batch counter; null (one batch a warp) under SDF_WARP_QUEUE=off,
    /// for measurement.
    unsigned long long* warp_queue() const;

    BvhGpuKernel kernel_;
    std::unique_ptr<DeviceBvh<float>> tree_float_;    ///< precision float
    std::unique_ptr<DeviceBvh<double>> tree_double_;  ///< precision double
    bool built_ = false;          ///< this binding built the tree (the host's, or on the device)
    nlohmann::json bvh_stats_;    ///< the build statistics of the tree, with where it was built

    mutable std::mutex mutex_;    ///< one call at a time: the scratch below and the certificate's counters
    mutable DeviceBuffer<unsigned long long> candidate_stats_;
    mutable DeviceBuffer<unsigned long long> warp_queue_;  ///< the warp searches' batch counter (WarpBatches)
    mutable StagedCopy staged_;   ///< query_host()'s pinned buffers
    mutable DeviceBuffer<char> host_query_points_;
    mutable DeviceBuffer<double> host_query_distance_, host_query_gradient_;
    mutable DeviceBuffer<int32_t> host_query_triangle_;
    mutable StoredSlabBuffers stored_buffers_;  ///< sample_slab_stored(): the slab's device bytes and pinned host copies
};

}  // namespace sdf::cuda
