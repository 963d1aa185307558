// The CUDA BVH sampler: uploads the BVH (nodes, packed triangles in BVH order) and the
// double mesh, cuts the lattice into slabs of z-layers that fit GPU memory, runs the BVH
// search and the double-precision finalize on each, and scatters the results (or, for the
// streamed writer, stores them on the device in the field file's bytes: stored_output.cuh).
#include "cuda/bvh_sampler.h"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <future>
#include <stdexcept>
#include <string>

#include "core/bvh/triangle_bvh.h"
#include "core/parallel/task_monitor.h"
#include "core/sampling/certified_search.h"
#include "core/sampling/narrow_band.h"
#include "core/sampling/sampler_results.h"
#include "core/winding/winding_sign.h"
#include <cub/device/device_radix_sort.cuh>

#include "cuda/bvh_candidates_kernel.cuh"
#include "cuda/bvh_kernel.cuh"
#include "cuda/bvh_warp_kernel.cuh"
#include "cuda/certify_kernel.cuh"
#include "kernels/core/morton.h"
#include "cuda/cuda_check.h"
#include "cuda/cuda_device.h"
#include "cuda/device_buffer.h"
#include "cuda/device_bvh_build.h"
#include "cuda/device_mesh.h"
#include "cuda/device_points.cuh"
#include "cuda/device_winding.h"
#include "cuda/finalize_kernel.cuh"
#include "cuda/launch_util.cuh"
#include "cuda/staged_copy.h"
#include "cuda/stored_output.cuh"

namespace sdf::cuda {
namespace {

__global__ void morton_keys(const Vec3d* points, int64_t n, Vec3d lo, double inv_side, uint64_t* keys, int64_t* identity) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const Vec3d p = points[i];
    keys[i] = morton_key_of_point(p.x, p.y, p.z, lo.x, lo.y, lo.z, inv_side);
    identity[i] = i;
}

__global__ void gather_points(const Vec3d* points, const int64_t* order, int64_t n, Vec3d* sorted) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < n) sorted[i] = points[order[i]];
}

/// A BVH and the double mesh on the device, for one precision of the search, with the
/// winding moments when the sign (prepared for this mesh) is the winding number's.
template <typename T>
struct DeviceBvh {
    DeviceBuffer<BvhNode> nodes;
    DeviceBuffer<PackedTriangle<T>> packed;
    DeviceBuffer<int32_t> triangle_index;
    DeviceBuffer<int32_t> source_triangle;  ///< prepared -> mesh file face order (stored slabs)
    DeviceBuffer<PackedTriangle<double>> exact;  ///< a host tree's double constants (float search's certificate)
    DeviceBuffer<int32_t> slot_of;               ///< a host tree's slot of every triangle (the same)
    std::unique_ptr<DeviceMesh<double>> mesh;
    DeviceWinding winding;
    std::unique_ptr<DeviceCertifier> certifier;  ///< float only (certify_kernel.cuh)
    BvhView<T> view{};
    bool solid = false;  ///< auto would sign this mesh by pseudonormals (the narrow band's brick skip)

    /// A tree built on the host: its nodes and triangle order and the double mesh go up once
    /// (the search, the certificate and the winding walk share them); the packed constants
    /// in tree order are made on the device from the mesh (the host's bits, and 29 MB less
    /// to copy at 100k triangles). The winding moments follow with add_winding().
    DeviceBvh(const TriangleBvh& bvh, const PreparedMesh& prepared)
        : solid(choose_sign_mode(prepared.report(), SignMode::Auto).mode == SignMode::Pseudonormal) {
        mesh = std::make_unique<DeviceMesh<double>>(prepared.buffers<double>());
        nodes.upload(bvh.nodes);
        triangle_index.upload(bvh.triangle_index);
        source_triangle.upload(prepared.source_triangle());
        const int n = int(bvh.triangle_index.size());
        const MeshView<double> m = mesh->view();
        packed.allocate(size_t(n));
        if constexpr (std::is_same_v<T, float>) {
            exact.allocate(size_t(n));
            slot_of.allocate(size_t(n));
            pack_in_slot_order(m.vertices, m.triangles, triangle_index.get(), n, packed.get(), exact.get(), slot_of.get());
            view = {nodes.get(), packed.get(), triangle_index.get(), int(bvh.nodes.size()), n};
            certifier = std::make_unique<DeviceCertifier>(view, exact.get(), slot_of.get(), prepared.search_bound());
        } else {
            pack_in_slot_order(m.vertices, m.triangles, triangle_index.get(), n, nullptr, packed.get(), nullptr);
            view = bvh.view<double>().with_arrays(nodes.get(), packed.get(), triangle_index.get());  // and its margin
        }
    }

    /// The winding moments of `sign` (prepared for this mesh over `bvh`, this tree) beside it.
    void add_winding(const SamplerSign& sign, const TriangleBvh& bvh) {
        winding.upload_moments(sign, bvh, nodes.get(), triangle_index.get(), mesh->view());
    }

    /// The BVH built on the device (cuda/device_bvh_build.h), with its winding moments;
    /// `device_mesh` is the double mesh it was built from. Nothing is copied.
    DeviceBvh(std::unique_ptr<DeviceLbvh> built, std::unique_ptr<DeviceMesh<double>> device_mesh,
              const PreparedMesh& prepared, const SamplerSign& sign)
        : mesh(std::move(device_mesh)),
          solid(choose_sign_mode(prepared.report(), SignMode::Auto).mode == SignMode::Pseudonormal),
          lbvh(std::move(built)) {
        source_triangle.upload(prepared.source_triangle());
        winding.adopt(sign, lbvh->nodes.get(), lbvh->moments.get(), lbvh->triangle_index.get(), lbvh->num_nodes, mesh->view());
        view = lbvh->view<T>();
        if constexpr (std::is_same_v<T, float>)
            certifier = std::make_unique<DeviceCertifier>(view, lbvh->packed_double.get(), lbvh->slot_of.get(), lbvh->bound);
    }
    std::unique_ptr<DeviceLbvh> lbvh;  ///< owns the arrays of `view` when built on the device
};

/// Points per thread of the warp search over `n` listed points on a GPU of `sms`
/// multiprocessors: 4, the lattice's, where the list fills the GPU's resident warps many
/// times over; fewer for sparser lists, whose 128-point warps leave the GPU to a few long,
/// divergent traversals. Measured on an H200 (docs/gpu-notes.md): 1M points 6.1 -> 5.6 ms
/// uniform, 6.9 -> 6.1 ms near the surface at 2; 16.8M points fastest at 4.
/// SDF_LIST_RUN (1, 2 or 4) overrides the rule, for measurement.
int list_points_per_thread(int64_t n, int sms) {
    static const int forced = [] {
        const char* e = std::getenv("SDF_LIST_RUN");
        const int v = e ? std::atoi(e) : 0;
        return v == 1 || v == 2 || v == 4 ? v : 0;
    }();
    if (forced) return forced;
    const int64_t resident_warps = int64_t(sms) * kFusedMinBlocks * (kBvhThreads / 32);
    if (n / (32 * 4) >= 16 * resident_warps) return 4;
    if (n / (32 * 2) >= 2 * resident_warps) return 2;
    return 1;
}

/// The current device's multiprocessors.
int multiprocessors() {
    int device = 0, sms = 1;
    CUDA_CHECK(cudaGetDevice(&device));
    CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
    return sms;
}

/// Certifies a float search's `nearest` (certify_kernel.cuh); double searches are the reference.
template <typename T, typename Piece>
void certify(const DeviceBvh<T>& dev, const Piece& piece, double point_coordinate, int* nearest) {
    if constexpr (std::is_same_v<T, float>) dev.certifier->certify(piece, point_coordinate, nearest);
}

/// The certificate fused into the warp kernel (float, and a bound that certifies at these
/// points); none (exact == nullptr: the separate pass certifies) otherwise.
template <typename T>
StreamedCertify streamed_certify(const DeviceBvh<T>& dev, BvhGpuKernel kernel, double point_coordinate) {
    if constexpr (std::is_same_v<T, float>)
        if (kernel == BvhGpuKernel::Warp) return dev.certifier->streamed(point_coordinate);
    return {};
}

/// Zeroes the certifier's counters.
template <typename T>
void reset_certificate(const DeviceBvh<T>& dev) {
    if constexpr (std::is_same_v<T, float>) dev.certifier->reset();
}

/// Reads them into `counters`.
template <typename T>
void read_certificate(const DeviceBvh<T>& dev, CertificateCounters& counters) {
    if constexpr (std::is_same_v<T, float>) dev.certifier->read(counters);
}

/// Per-piece results on the device: the search's nearest triangle, then the finalized samples.
struct PieceResults {
    DeviceBuffer<int> nearest;
    DevicePieceResults samples;
    static size_t bytes_per_point() { return sizeof(int) + DevicePieceResults::bytes_per_point(); }

    explicit PieceResults(int64_t n) : nearest{size_t(n)}, samples(n) {}
    PieceOutputs outputs() const { return samples.outputs(); }
    HostPieceResults download(int64_t n) const { return samples.download(n); }
};

class CudaBvhSampler final : public Sampler {
public:
    explicit CudaBvhSampler(const SamplerOptions& options) : options_(options), sign_(options.sign) {
        kernel_ = kernel_from_name(kCudaBvhKernels, options.kernel, "CUDA BVH");
    }

    std::string name() const override { return std::string("cuda/bvh/") + kernel_name(); }

    SampledField sample_slab(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab) override {
        return options_.precision == Precision::Float ? sample_as<float>(mesh, lattice, slab) : sample_as<double>(mesh, lattice, slab);
    }

    std::optional<StoredSlab> sample_slab_stored(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab,
                                                 const StoredLayout& layout) override {
        return options_.precision == Precision::Float ? sample_stored_as<float>(mesh, lattice, slab, layout)
                                                      : sample_stored_as<double>(mesh, lattice, slab, layout);
    }

    std::vector<PointSample> query(const PreparedMesh& mesh, const std::vector<Vec3d>& points) override {
        require_search_range(mesh, points, options_.precision);
        return options_.precision == Precision::Float ? query_as<float>(mesh, points) : query_as<double>(mesh, points);
    }

    bool query_device(const PreparedMesh& mesh, const DevicePoints& points, const DeviceQueryResults& results) override {
        if (points.device != options_.device)
            throw std::invalid_argument("CUDA BVH sampler: the points are on CUDA device " + std::to_string(points.device) +
                                        ", the sampler on device " + std::to_string(options_.device));
        if (points.count < 0 || (points.count > 0 && points.xyz == nullptr))
            throw std::invalid_argument("CUDA BVH sampler: no device points (count " + std::to_string(points.count) + ")");
        if (points.count == 0) return true;
        if (options_.precision == Precision::Float) query_device_as<float>(mesh, points, results);
        else query_device_as<double>(mesh, points, results);
        return true;
    }

    /// Host arrays in and out (a NumPy array's buffer): the caller's bytes go to the device as
    /// they are (float32 stays float32 on the bus) through pinned buffers, the search is
    /// query_device()'s, and the result columns come back through pinned buffers straight into
    /// the caller's arrays: no conversion, no host scatter, the copies overlapped.
    void query_host(const PreparedMesh& mesh, const HostPoints& points, const HostQueryResults& results) override {
        if (points.count <= 0) return;
        const auto start = std::chrono::steady_clock::now();
        require_finite_points(points, "points", options_.threads);
        CUDA_CHECK(cudaSetDevice(options_.device));
        std::vector<Vec3d> gathered;  // only for rows that are not one block of bytes
        const void* source = points.xyz;
        size_t bytes = points.bytes();
        DevicePoints on_device{nullptr, points.float32, points.count, 3, 1, options_.device, nullptr};
        if (!points.contiguous()) {
            gathered = gather_points(points, "points", options_.threads);
            source = gathered.data();
            bytes = gathered.size() * sizeof(Vec3d);
            on_device.float32 = false;
        }
        grow(host_query_points_, bytes);
        staged_.to_device(source, host_query_points_.get(), bytes);
        on_device.xyz = host_query_points_.get();
        const auto uploaded = std::chrono::steady_clock::now();
        const size_t n = size_t(points.count);
        DeviceQueryResults columns;
        if (results.distance) columns.distance = grow(host_query_distance_, n);
        if (results.gradient) columns.gradient = grow(host_query_gradient_, 3 * n);
        if (results.triangle) columns.triangle = grow(host_query_triangle_, n);
        {
            // The caller's result arrays are mapped on other threads while the device searches.
            std::future<void> mapped = std::async(std::launch::async, [&] {
                if (results.distance) StagedCopy::map_pages(results.distance, n * sizeof(double));
                if (results.gradient) StagedCopy::map_pages(results.gradient, 3 * n * sizeof(double));
                if (results.triangle) StagedCopy::map_pages(results.triangle, n * sizeof(int32_t));
            });
            query_device(mesh, on_device, columns);
            mapped.get();
        }
        const auto searched = std::chrono::steady_clock::now();
        if (results.distance) staged_.to_host(columns.distance, results.distance, n * sizeof(double));
        if (results.gradient) staged_.to_host(columns.gradient, results.gradient, 3 * n * sizeof(double));
        if (results.triangle) staged_.to_host(columns.triangle, results.triangle, n * sizeof(int32_t));
        const auto end = std::chrono::steady_clock::now();
        using seconds = std::chrono::duration<double>;
        query_timings_.upload += seconds(uploaded - start).count();
        query_timings_.download = seconds(end - searched).count();
        query_timings_.total = seconds(end - start).count();
    }

private:
    const char* kernel_name() const { return sdf::kernel_name(kCudaBvhKernels, kernel_); }

    /// `buffer` with room for `count` elements (kept between queries: a bound SDF queried many
    /// times allocates once).
    template <typename E>
    static E* grow(DeviceBuffer<E>& buffer, size_t count) {
        if (buffer.size() < count) buffer.allocate(count);
        return buffer.get();
    }

    /// The device copy of this mesh's BVH, uploaded when the mesh (or precision) changes.
    template <typename T>
    const DeviceBvh<T>& device_bvh(const PreparedMesh& mesh, bool& built, bool& uploaded, EventTimer& upload) {
        CUDA_CHECK(cudaSetDevice(options_.device));
        if (const DeviceBvh<T>* dev = built_on_device<T>(mesh, built, uploaded, upload)) return *dev;
        const auto bvh = mesh.bvh(&built);  // the mesh's own, built once
        std::unique_ptr<DeviceBvh<T>>& slot = slot_of<T>();
        // host_bvh_ holds the tree uploaded last, so no other mesh's tree can have its address.
        uploaded = !slot || host_bvh_ != bvh;
        if (!uploaded) {
            sign_.prepare(mesh);  // the same tree: its winding sign is kept
        } else {
            device_float_.reset();
            device_double_.reset();
            upload.begin();
            // The winding moments (on the host's threads, over this tree) while the tree and
            // the mesh go up: neither waits for the other.
            // The caller's task monitor goes along: the sign's "auto" warning reaches Python's
            // SdfWarning, and a stop request stops the moments.
            std::future<void> sign = std::async(std::launch::async, [&, monitor = current_task_monitor()] {
                const ScopedTaskMonitor scope(monitor);
                sign_.prepare(mesh);
            });
            std::unique_ptr<DeviceBvh<T>> dev;
            try {
                dev = std::make_unique<DeviceBvh<T>>(*bvh, mesh);
            } catch (...) {
                sign.wait();
                throw;
            }
            sign.get();
            dev->add_winding(sign_, *bvh);
            slot = std::move(dev);
            upload.end();
            host_bvh_ = bvh;
            device_mesh_ = 0;
            bvh_stats_ = bvh->stats.to_json();
            bvh_stats_["built_on"] = "host";
            if (!device_build_skipped_.empty()) bvh_stats_["device_build_skipped"] = device_build_skipped_;
        }
        return *slot;
    }

    /// The BVH built on the device (bvh_build "device" or "auto": the field does not depend
    /// on the tree, docs/bvh.md, "Build on the GPU", and docs/winding.md, the certified sign);
    /// null where the host builds it (also when the device tree is too deep: said in the
    /// provenance's bvh.device_build_skipped).
    template <typename T>
    const DeviceBvh<T>* built_on_device(const PreparedMesh& mesh, bool& built, bool& uploaded, EventTimer& upload) {
        device_build_skipped_.clear();
        // Auto builds on the device for either sign: the pseudonormal sign and the certified
        // winding sign (kernels/winding/certified_winding.h) do not depend on the tree.
        if (options_.bvh_build == BvhBuildSite::Host) return nullptr;
        // A mesh's id() is never another mesh's, even one made where a freed mesh was.
        const uint64_t key = mesh.id();
        std::unique_ptr<DeviceBvh<T>>& slot = slot_of<T>();
        built = uploaded = false;
        if (slot && slot->lbvh && device_mesh_ == key) return slot.get();
        if (device_failed_ == key) {  // this mesh's device tree was too deep: do not build it again
            device_build_skipped_ = device_failed_reason_;
            return nullptr;
        }
        sign_.prepare_mode(mesh);
        device_float_.reset();
        device_double_.reset();
        upload.begin();
        // The whole mesh first: its normals' copy from pageable memory beside the build (another
        // host thread, another stream) made the build 1.5-2 ms slower and the first call no
        // faster (H100, docs/gpu-notes.md).
        auto dmesh = std::make_unique<DeviceMesh<double>>(mesh.buffers<double>());
        std::unique_ptr<DeviceLbvh> lbvh = build_lbvh_on_device(mesh, dmesh->view().vertices, dmesh->view().triangles);
        if (!lbvh || !lbvh->within_depth) {
            upload.end();
            device_build_skipped_ = lbvh ? "the device tree is deeper than kBvhMaxDepth = " + std::to_string(kBvhMaxDepth) +
                                               " (depth " + std::to_string(lbvh->stats.depth) + ")"
                                         : "the mesh fits one leaf";
            device_mesh_ = 0;
            device_failed_ = key;
            device_failed_reason_ = device_build_skipped_;
            return nullptr;
        }
        bvh_stats_ = lbvh->stats.to_json();
        bvh_stats_["built_on"] = "device";
        bvh_stats_["builder"] = gpu_bvh_builder_name(GpuBvhBuildOptions{}.builder);
        bvh_stats_["device_seconds"] = lbvh->device_seconds;
        sign_.set_external_moments(lbvh->device_seconds, "device");
        slot = std::make_unique<DeviceBvh<T>>(std::move(lbvh), std::move(dmesh), mesh, sign_);
        upload.end();
        built = uploaded = true;
        device_mesh_ = key;
        host_bvh_.reset();
        return slot.get();
    }

    template <typename T>
    std::unique_ptr<DeviceBvh<T>>& slot_of() {
        if constexpr (std::is_same_v<T, float>) return device_float_;
        else return device_double_;
    }

    /// z-layers per slab: as many as 80% of free GPU memory holds (and max_points_per_piece).
    int layers_per_slab(const GridBlock& block) const {
        const size_t free_bytes = free_device_memory();
        const int64_t layer = int64_t(block.resolution.x) * block.resolution.y;
        int64_t points = int64_t(0.8 * double(free_bytes)) / int64_t(PieceResults::bytes_per_point());
        if (options_.max_points_per_piece > 0) points = std::min(points, options_.max_points_per_piece);
        const int64_t layers = points / std::max<int64_t>(1, layer);
        if (layers < 1 && options_.max_points_per_piece <= 0)
            throw std::runtime_error("CUDA BVH sampler: " + std::to_string(free_bytes >> 20) +
                                     " MiB of free GPU memory cannot hold one z-layer of " + std::to_string(layer) + " points");
        return int(std::clamp<int64_t>(layers, 1, block.resolution.z));
    }

    /// The band's search parameters (bricks outside it are skipped by "warp" and "candidates";
    /// the other kernels search everything and finalize_samples() applies the band).
    template <typename T>
    BandSearch band_search(const DeviceBvh<T>& dev) const {
        const bool winding = dev.winding.view().enabled();
        return {options_.band_width, dev.mesh->view(), winding, winding || dev.solid};
    }

    template <typename T>
    void launch_slab(const DeviceBvh<T>& dev, const GridRangePiece& piece, const SlabGeometry& slab, const StreamedCertify& cert,
                     int* nearest) {
        const int blocks = blocks_for(slab.threads(), kBvhThreads);
        const BvhView<T>& view = dev.view;
        switch (kernel_) {
            case BvhGpuKernel::Brick:
                nearest_triangle_bvh_slab<T, BvhGpuKernel::Brick><<<blocks, kBvhThreads>>>(view, piece, slab, nearest);
                break;
            case BvhGpuKernel::Seeded:
                nearest_triangle_bvh_slab<T, BvhGpuKernel::Seeded><<<blocks, kBvhThreads>>>(view, piece, slab, nearest);
                break;
            case BvhGpuKernel::Unseeded:
                nearest_triangle_bvh_slab<T, BvhGpuKernel::Unseeded><<<blocks, kBvhThreads>>>(view, piece, slab, nearest);
                break;
            case BvhGpuKernel::Warp:
                launch_bvh_warp(blocks, view, SlabLayout{piece, slab}, band_search(dev), cert, nearest);
                break;
            case BvhGpuKernel::Candidates:
                nearest_triangle_bvh_candidates<T><<<blocks, kBvhThreads>>>(view, SlabLayout{piece, slab}, band_search(dev),
                                                                            nearest, candidate_stats_.get());
                break;
        }
        CUDA_CHECK_LAUNCH("nearest_triangle_bvh_slab");
    }

    /// Searches and finalizes z-layers [z0, z0 + nz) of `block`; `sink(results, count)` then
    /// takes the piece's device results (to download and scatter, or to store on the device).
    template <typename T, typename Sink>
    void run_slab(const DeviceBvh<T>& dev, const Lattice& lattice, const GridBlock& block, int z0, int nz, EventTimer& compute,
                  Sink sink) {
        const int64_t layer = int64_t(block.resolution.x) * block.resolution.y;
        const GridRangePiece piece{lattice, block, z0 * layer, nz * layer};
        const SlabGeometry slab{block.resolution, z0, nz};
        PieceResults r(piece.count);
        compute.begin();
        const double coordinate = largest_lattice_coordinate(lattice);
        const StreamedCertify fused = streamed_certify(dev, kernel_, coordinate);
        launch_slab<T>(dev, piece, slab, fused, r.nearest.get());
        if (!fused.exact) certify(dev, piece, coordinate, r.nearest.get());
        launch_finalize_samples(piece.count, dev.mesh->view(), piece, r.nearest.get(), dev.winding.view(),
                                options_.band_width, r.outputs());
        CUDA_CHECK_LAUNCH("finalize_samples (bvh slab)");
        compute.end();
        sink(r, piece.count);
    }

    /// Runs every piece of the slab's blocks through run_slab; returns the points computed
    /// and the pieces (GPU memory decides how many z-layers a piece holds).
    template <typename T, typename Sink>
    std::pair<int64_t, int64_t> run_blocks(const DeviceBvh<T>& dev, const Lattice& lattice, const LatticeSlab& slab,
                                           EventTimer& compute, Sink sink) {
        GridBlock blocks[kMaxSamplingBlocks];
        const int nblocks = slab_sampling_blocks(lattice, options_.bcc_strategy, slab, blocks);
        int64_t computed = 0, pieces = 0;
        reset_certificate(dev);
        if (kernel_ == BvhGpuKernel::Candidates) {
            if (candidate_stats_.size() == 0) candidate_stats_.allocate(4);
            CUDA_CHECK(cudaMemset(candidate_stats_.get(), 0, 4 * sizeof(unsigned long long)));
        }
        for (int b = 0; b < nblocks; ++b) {
            const GridBlock block = blocks[b];
            const int layers = layers_per_slab(block);
            for (int z0 = 0; z0 < block.resolution.z; z0 += layers, ++pieces)
                run_slab<T>(dev, lattice, block, z0, std::min(layers, block.resolution.z - z0), compute, sink);
            computed += block.count();
        }
        return {computed, pieces};
    }

    template <typename T>
    SampledField sample_as(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab) {
        const auto start = std::chrono::steady_clock::now();
        require_band_width(options_.band_width, "sampler band_width");
        EventTimer upload, compute, download;
        bool built = false, uploaded = false;
        const DeviceBvh<T>& dev = device_bvh<T>(mesh, built, uploaded, upload);
        require_search_range(mesh, lattice, options_.precision);
        // Results made on the device in the field's own layout (the stored path with float64
        // channels, stored_output.cuh) and copied once through pinned buffers straight into the
        // field's arrays: no per-piece pageable copy, no host scatter. A slab whose channels do
        // not fit a quarter of the free device memory takes the per-piece path below.
        const int64_t points = slab_point_count(lattice, slab);
        const StoredLayout layout{false, true, true};
        const size_t free_bytes = free_device_memory();
        if (points > 0 && double(points) * double(layout.bytes_per_point()) <= 0.25 * double(free_bytes)) {
            // The field's host arrays (each page mapped at its first write) are made on other
            // threads while the device computes.
            std::future<SampledField> made =
                std::async(std::launch::async, [&] { return unfilled_field(mesh, lattice, slab, options_.precision); });
            const StoredChannels<double> out = stored_buffers_.device_channels<double>(points, layout, dev.source_triangle.get());
            const auto [computed, pieces] = store_blocks<T, double>(dev, lattice, slab, out, compute);
            SampledField field = made.get();
            download.begin();
            const size_t n = size_t(points);
            staged_.to_host(out.distance, field.distance.data(), n * sizeof(double));
            staged_.to_host(out.gradient, field.gradient.data(), 3 * n * sizeof(double));
            staged_.to_host(out.triangle, field.closest_triangle.data(), n * sizeof(int32_t));
            download.end();
            record_provenance(field, mesh, lattice, upload, compute, download, computed, pieces, built, uploaded, start);
            record_search_certificate(dev, field);
            if (options_.band_width > 0) field.sampler.band = band_provenance(mesh, count_narrow_band(field));
            return field;
        }
        SampledField field = unfilled_field(mesh, lattice, slab, options_.precision);
        auto sink = [&](const PieceResults& r, int64_t count) {
            download.begin();
            const HostPieceResults h = r.download(count);
            download.end();
            scatter_batch(h, mesh, field);
        };
        const auto [computed, pieces] = run_blocks<T>(dev, lattice, slab, compute, sink);
        record_provenance(field, mesh, lattice, upload, compute, download, computed, pieces, built, uploaded, start);
        record_search_certificate(dev, field);
        if (options_.band_width > 0) field.sampler.band = band_provenance(mesh, count_narrow_band(field));
        return field;
    }

    /// sample_as() with the results stored on the device in the field file's bytes
    /// (stored_output.cuh) and brought to the host in one pinned copy.
    template <typename T>
    std::optional<StoredSlab> sample_stored_as(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab,
                                               const StoredLayout& layout) {
        const auto start = std::chrono::steady_clock::now();
        require_band_width(options_.band_width, "sampler band_width");
        EventTimer upload, compute, download;
        bool built = false, uploaded = false;
        const DeviceBvh<T>& dev = device_bvh<T>(mesh, built, uploaded, upload);
        StoredSlab stored;
        require_search_range(mesh, lattice, options_.precision);
        stored.info.lattice = lattice;
        stored.info.precision = options_.precision;
        const int64_t points = slab_point_count(lattice, slab);
        const int32_t* source = dev.source_triangle.get();
        const auto [computed, pieces] =
            layout.float32 ? store_blocks<T, float>(dev, lattice, slab, stored_buffers_.device_channels<float>(points, layout, source), compute)
                           : store_blocks<T, double>(dev, lattice, slab, stored_buffers_.device_channels<double>(points, layout, source),
                                                     compute);
        download.begin();
        stored_buffers_.download(points, layout, stored);
        download.end();
        record_provenance(stored.info, mesh, lattice, upload, compute, download, computed, pieces, built, uploaded, start);
        record_search_certificate(dev, stored.info);
        if (options_.band_width > 0) stored.info.sampler.band = band_provenance(mesh, stored.band);
        stored.info.sampler.details["stored_on_device"] = true;
        return stored;
    }

    template <typename T, typename F>
    std::pair<int64_t, int64_t> store_blocks(const DeviceBvh<T>& dev, const Lattice& lattice, const LatticeSlab& slab,
                                             const StoredChannels<F>& out, EventTimer& compute) {
        auto sink = [&](const PieceResults& r, int64_t count) {
            compute.begin();
            store_piece<F><<<blocks_for(count, 256), 256>>>(r.outputs(), count, out);
            CUDA_CHECK_LAUNCH("store_piece");
            compute.end();
        };
        return run_blocks<T>(dev, lattice, slab, compute, sink);
    }

    /// Timings and the provenance every slab records (sampler, plan, BVH, device, candidates).
    void record_provenance(SampledField& field, const PreparedMesh& mesh, const Lattice& lattice, const EventTimer& upload,
                           const EventTimer& compute, const EventTimer& download, int64_t computed, int64_t pieces, bool built,
                           bool uploaded, std::chrono::steady_clock::time_point start) {
        field.timings.upload = upload.seconds();
        field.timings.kernel = compute.seconds();
        field.timings.download = download.seconds();
        field.timings.point_triangle_pairs = double(computed) * double(mesh.triangles().size());  // brute-force equivalent
        field.timings.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        nlohmann::json bvh_info = bvh_stats_;
        bvh_info["built_by_this_call"] = built;
        bvh_info["uploaded_by_this_call"] = uploaded;
        field.sampler = sampler_provenance("cuda", "bvh", kernel_name(), options_, lattice, computed, sign_);
        field.sampler.details["plan"] = {{"pieces", pieces}, {"threads_per_block", kBvhThreads}, {"points_per_thread", kRunPoints}};
        field.sampler.details["bvh"] = bvh_info;
        field.sampler.details["device"] = describe_device(options_.device);
        if (kernel_ == BvhGpuKernel::Candidates) {
            unsigned long long counts[4] = {0, 0, 0, 0};
            candidate_stats_.download(counts, 4);
            CUDA_CHECK(cudaStreamSynchronize(0));
            const double bricks = double(counts[0]);
            field.sampler.details["candidates"] = {{"bricks_searched", counts[0]},
                                           {"bricks_outside_band", counts[2]},
                                           {"mean_candidate_triangles", bricks > 0 ? double(counts[1]) / bricks : 0.0},
                                           {"mean_leaf_ranges", bricks > 0 ? double(counts[3]) / bricks : 0.0},
                                           {"points_per_brick", 32 * kRunPoints}};
        }
    }

    /// The certificate's counters of the float search (certify_kernel.cuh) in the timings and
    /// the provenance; double searches are the reference and record themselves as such.
    template <typename T>
    void record_search_certificate(const DeviceBvh<T>& dev, SampledField& field) const {
        CertificateCounters certificate;
        read_certificate(dev, certificate);
        record_certificate(field.timings, certificate);
        field.sampler.search_certificate = certificate_provenance(std::is_same_v<T, float>, true, certificate);
        dev.winding.record_counts(field.sampler);  // the certified winding sign's counters (beside the search's)
    }

    BandReport band_provenance(const PreparedMesh& mesh, const NarrowBandCounts& counts) const {
        const bool skips = (kernel_ == BvhGpuKernel::Warp || kernel_ == BvhGpuKernel::Candidates) &&
                           (sign_.winding() || choose_sign_mode(mesh.report(), SignMode::Auto).mode == SignMode::Pseudonormal);
        return narrow_band_provenance(options_.band_width, counts, skips ? "bricks skipped by the distance bound" : "post-processed");
    }

    /// Point lists: Morton keys in the mesh's box, a device radix sort, then the warp search
    /// over 128 consecutive sorted points (neighbours in space) and the finalize, whose
    /// output_index sends every result back to its input position.
    template <typename T>
    std::vector<PointSample> query_as(const PreparedMesh& mesh, const std::vector<Vec3d>& points) {
        // The vector first, pageable copies: making it on another thread while the device
        // works measured 2.5-3x slower (16.8M points, H200: 0.30-0.39 against 0.11-0.13 s),
        // with staged (pinned) copies too (0.37 against 0.17 s), and a new sampler's pinned
        // buffers cost a one-point query 15 ms (docs/gpu-notes.md).
        std::vector<PointSample> out(points.size());
        if (points.empty()) return out;
        EventTimer upload, compute, download;
        bool built = false, uploaded = false;
        const DeviceBvh<T>& dev = device_bvh<T>(mesh, built, uploaded, upload);
        const auto start = std::chrono::steady_clock::now();
        const int64_t n = int64_t(points.size());
        DeviceBuffer<Vec3d> device_points{size_t(n)};
        upload.begin();
        device_points.upload(points);
        upload.end();
        DeviceBuffer<PointSample> device_out{size_t(n)};
        const double coordinate = largest_coordinate(points);
        CertificateCounters certificate;
        search_points<T>(mesh, dev, device_points.get(), n, coordinate, compute, certificate, [&](const PieceResults& r, int64_t count) {
            store_point_samples<<<blocks_for(count, 256), 256>>>(r.outputs(), count, dev.source_triangle.get(),
                                                                  device_out.get());
            CUDA_CHECK_LAUNCH("store_point_samples");
        });
        // The results are in input order on the device already: one copy, no host scatter.
        download.begin();
        device_out.download(out.data(), out.size());
        download.end();
        record_query_timings(mesh, n, upload, compute, download, start);
        record_certificate(query_timings_, certificate);
        return out;
    }

    /// query_as() for points already on the device, results written to the caller's device
    /// arrays (core/sampling/device_query.h); no host copy of either.
    template <typename T>
    void query_device_as(const PreparedMesh& mesh, const DevicePoints& points, const DeviceQueryResults& results) {
        require_search_range(mesh, options_.precision);
        EventTimer upload, compute, download;
        bool built = false, uploaded = false;
        const DeviceBvh<T>& dev = device_bvh<T>(mesh, built, uploaded, upload);
        const auto start = std::chrono::steady_clock::now();
        const int64_t n = points.count;
        // Work already queued on the caller's stream (that made the points) comes first.
        CUDA_CHECK(cudaStreamSynchronize(static_cast<cudaStream_t>(points.stream)));
        DeviceBuffer<Vec3d> device_points{size_t(n)};
        const double coordinate = read_points(points, device_points.get());
        CertificateCounters certificate;
        search_points<T>(mesh, dev, device_points.get(), n, coordinate, compute, certificate, [&](const PieceResults& r, int64_t count) {
            store_point_columns<<<blocks_for(count, 256), 256>>>(r.outputs(), count, dev.source_triangle.get(), results);
            CUDA_CHECK_LAUNCH("store_point_columns");
        });
        CUDA_CHECK(cudaStreamSynchronize(0));
        record_query_timings(mesh, n, upload, compute, download, start);
        record_certificate(query_timings_, certificate);
    }

    /// The caller's points as doubles in `out`, refused (naming the first) where a point is
    /// not finite or beyond the search's range: only that point is copied to the host.
    /// Returns their largest |coordinate| (the certified search's bound needs it).
    double read_points(const DevicePoints& points, Vec3d* out) {
        DeviceBuffer<unsigned long long> first_bad{2};  // [0]: first bad index, [1]: largest |coordinate|'s bits
        const unsigned long long init[2] = {~0ull, 0ull};
        const unsigned long long none = init[0];
        CUDA_CHECK(cudaMemcpy(first_bad.get(), init, sizeof init, cudaMemcpyHostToDevice));
        const double limit = largest_search_coordinate(options_.precision);
        const int blocks = blocks_for(points.count, 256);
        if (points.float32)
            read_device_points<<<blocks, 256>>>(static_cast<const float*>(points.xyz), points.count, points.row_stride,
                                                points.column_stride, limit, out, first_bad.get());
        else
            read_device_points<<<blocks, 256>>>(static_cast<const double*>(points.xyz), points.count, points.row_stride,
                                                points.column_stride, limit, out, first_bad.get());
        CUDA_CHECK_LAUNCH("read_device_points");
        unsigned long long result[2] = {none, 0};
        CUDA_CHECK(cudaMemcpy(result, first_bad.get(), sizeof result, cudaMemcpyDeviceToHost));
        if (result[0] != none) {
            Vec3d p;
            CUDA_CHECK(cudaMemcpy(&p, out + result[0], sizeof p, cudaMemcpyDeviceToHost));
            require_query_point_in_range(p, int64_t(result[0]), options_.precision);
        }
        double largest = 0;
        std::memcpy(&largest, &result[1], sizeof largest);
        return largest;
    }

    /// Morton sort, warp (or candidates) search and finalize of n device points, piece by
    /// piece; `store(results, count)` takes each piece's results to their input positions, and
    /// `certificate` the float search's certificate counters.
    template <typename T, typename Store>
    void search_points(const PreparedMesh& mesh, const DeviceBvh<T>& dev, const Vec3d* device_points, int64_t n,
                       double coordinate, EventTimer& compute, CertificateCounters& certificate, Store store) {
        reset_certificate(dev);
        // Every device buffer is allocated before the timed work (allocation is not search).
        DeviceBuffer<Vec3d> sorted_points{size_t(n)};
        DeviceBuffer<int64_t> order{size_t(n)};
        MortonSort sort(n);
        int64_t step = n;
        if (options_.max_points_per_piece > 0) step = std::min(step, options_.max_points_per_piece);
        PieceResults r(step);  // reused by every piece
        const int run = list_points_per_thread(step, multiprocessors());
        for (int64_t begin = 0; begin < n; begin += step) {
            compute.begin();
            if (begin == 0) sort.run(mesh, device_points, sorted_points.get(), order.get());
            const SortedPointListPiece piece{sorted_points.get(), order.get(), begin, std::min(step, n - begin)};
            const PointListPiece list{sorted_points.get(), begin, piece.count};
            const StreamedCertify fused = streamed_certify(dev, kernel_, coordinate);
            const auto warp = [&](auto layout) {
                launch_bvh_warp(blocks_for(layout.threads(), kBvhThreads), dev.view, layout, BandSearch{}, fused, r.nearest.get());
            };
            if (kernel_ == BvhGpuKernel::Candidates) {
                const ListLayout layout{list};
                nearest_triangle_bvh_candidates<T><<<blocks_for(layout.threads(), kBvhThreads), kBvhThreads>>>(
                    dev.view, layout, BandSearch{}, r.nearest.get(), nullptr);
            } else if (run == 1) {
                warp(ListRuns<1>{list});
            } else if (run == 2) {
                warp(ListRuns<2>{list});
            } else {
                warp(ListLayout{list});
            }
            CUDA_CHECK_LAUNCH("nearest_triangle_bvh (sorted points)");
            if (!fused.exact) certify(dev, piece, coordinate, r.nearest.get());
            launch_finalize_samples(piece.count, dev.mesh->view(), piece, r.nearest.get(),
                                    dev.winding.view(), options_.band_width, r.outputs());
            CUDA_CHECK_LAUNCH("finalize_samples (bvh points)");
            store(r, piece.count);
            compute.end();
        }
        read_certificate(dev, certificate);
        dev.winding.discard_counts();  // a query has no report: its points are not the next sampling's
    }

    void record_query_timings(const PreparedMesh& mesh, int64_t n, const EventTimer& upload, const EventTimer& compute,
                              const EventTimer& download, std::chrono::steady_clock::time_point start) {
        query_timings_ = {};
        query_timings_.upload = upload.seconds();
        query_timings_.kernel = compute.seconds();
        query_timings_.download = download.seconds();
        query_timings_.point_triangle_pairs = double(n) * double(mesh.triangles().size());
        query_timings_.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    /// Sorts points by their Morton keys in the mesh's (cubic) box; the buffers (keys, CUB's
    /// temporary storage) are allocated by the constructor.
    struct MortonSort {
        int64_t n;
        DeviceBuffer<uint64_t> keys, keys_sorted;
        DeviceBuffer<int64_t> identity;
        DeviceBuffer<unsigned char> temp;
        size_t temp_bytes = 0;

        explicit MortonSort(int64_t count) : n(count), keys{size_t(count)}, keys_sorted{size_t(count)}, identity{size_t(count)} {
            CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, keys.get(), keys_sorted.get(), identity.get(),
                                                       identity.get(), n, 0, 63));
            temp.allocate(temp_bytes);
        }
        /// `sorted` receives the points in key order, `order` their input positions.
        void run(const PreparedMesh& mesh, const Vec3d* points, Vec3d* sorted, int64_t* order) {
            const Bounds3& box = mesh.bounds();
            const Vec3d extent = box.extent();
            const double side = std::max({extent.x, extent.y, extent.z, 1e-300});
            morton_keys<<<blocks_for(n, 256), 256>>>(points, n, box.min, 1.0 / side, keys.get(), identity.get());
            CUDA_CHECK_LAUNCH("morton_keys");
            CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp.get(), temp_bytes, keys.get(), keys_sorted.get(), identity.get(), order,
                                                       n, 0, 63));
            gather_points<<<blocks_for(n, 256), 256>>>(points, order, n, sorted);
            CUDA_CHECK_LAUNCH("gather_points");
        }
    };

    SamplerOptions options_;
    BvhGpuKernel kernel_ = BvhGpuKernel::Warp;
    SamplerSign sign_;
    std::shared_ptr<const TriangleBvh> host_bvh_;  ///< the mesh BVH the device copies were made of
    uint64_t device_mesh_ = 0;          ///< the id() of the mesh the device-built BVH belongs to (0: none)
    uint64_t device_failed_ = 0;        ///< the id() of the mesh whose device build fell back to the host
    std::string device_failed_reason_;
    nlohmann::json bvh_stats_;          ///< the build statistics of the BVH in use, with where it was built
    std::string device_build_skipped_;  ///< why the last device_bvh() call built on the host
    std::unique_ptr<DeviceBvh<float>> device_float_;
    std::unique_ptr<DeviceBvh<double>> device_double_;
    DeviceBuffer<unsigned long long> candidate_stats_;
    StagedCopy staged_;  ///< query_host()'s pinned buffers
    DeviceBuffer<char> host_query_points_;
    DeviceBuffer<double> host_query_distance_, host_query_gradient_;
    DeviceBuffer<int32_t> host_query_triangle_;
    StoredSlabBuffers stored_buffers_;  ///< sample_slab_stored(): the slab's device bytes and pinned host copies
};

}  // namespace

std::unique_ptr<Sampler> make_cuda_bvh_sampler(const SamplerOptions& options) {
    return std::make_unique<CudaBvhSampler>(options);
}

}  // namespace sdf::cuda
