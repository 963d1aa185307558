// The CUDA brute-force sampler: plans pieces (points) and chunks (triangles) that fit the
// GPU, runs the thesis or the tuned kernel on them, and scatters the results into a field.
#include "cuda/brute_force/cuda_sampler.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>

#include "core/bvh/triangle_bvh.h"
#include "core/sampling/backend_sampler.h"
#include "core/sampling/sampler_results.h"
#include "cuda/sampling/certify_kernel.cuh"
#include "cuda/util/cuda_check.h"
#include "cuda/util/cuda_device.h"
#include "cuda/util/device_buffer.h"
#include "cuda/util/device_guard.h"
#include "cuda/util/device_mesh.h"
#include "cuda/sampling/device_winding.h"
#include "cuda/sampling/finalize_kernel.cuh"
#include "cuda/sampling/launch_util.cuh"
#include "cuda/sampling/point_pieces.h"
#include "cuda/brute_force/thesis_kernel.cuh"
#include "cuda/brute_force/tuned_kernel.cuh"

namespace sdf::cuda {
namespace {

using CudaKernel = CudaBruteForceKernel;

constexpr int kFinalizeThreads = 256;

/// Everything one sampling call needs on the device, and its timers.
template <typename T>
class Engine {
public:
    using Sink = std::function<void(const HostPieceResults&)>;

    /// Over the bound sampler's device mesh and winding data (uploaded at binding).
    Engine(const PreparedMesh& mesh, const SamplerOptions& options, CudaKernel kernel, const DeviceMesh<double>& device_mesh,
           const DeviceWinding& winding)
        : host_(mesh.buffers<T>()), options_(options), kernel_(kernel), mesh_(device_mesh), winding_(winding),
          upload_(options.device), compute_(options.device), download_(options.device) {
        // The caller (the bound sampler) has made options.device current; the timers' events
        // are made there too (issue 36: they were made on device 0 before).
        cudaDeviceProp prop{};
        CUDA_CHECK(cudaGetDeviceProperties(&prop, options.device));
        sms_ = prop.multiProcessorCount;
        max_threads_per_sm_ = prop.maxThreadsPerMultiProcessor;
        const size_t free_bytes = free_device_memory();
        budget_ = size_t(0.8 * double(free_bytes));
        num_triangles_ = int(host_.triangles.size());
        if (kernel_ == CudaKernel::Tuned) plan_triangle_chunks();
        else prepare_thesis_chunks();
    }

    /// Certifies the tuned float search with `certifier` (certify_kernel.cuh) for points of
    /// largest |coordinate| `point_coordinate`.
    void certify_with(const DeviceCertifier* certifier, double point_coordinate) {
        certifier_ = certifier;
        point_coordinate_ = point_coordinate;
    }

    /// Runs every point of `piece`-shaped work [0, total) through the kernel, in pieces that
    /// fit, and hands each piece's results to `sink`. `make_piece(begin, count)` builds a piece.
    template <typename MakePiece>
    void run_tuned(int64_t total, MakePiece make_piece, const Sink& sink) {
        const int64_t step = tuned_piece_points(total);
        for (int64_t begin = 0; begin < total; begin += step) {
            auto piece = make_piece(begin, std::min(step, total - begin));
            sink(tuned_piece(piece));
            ++pieces_;
        }
    }

    /// The thesis's layout: pieces of whole 32^3 regions (several run concurrently).
    template <typename Piece>
    void run_thesis(const Piece& piece, const Sink& sink) { sink(thesis_piece(piece)); ++pieces_; }

    /// Regions the GPU runs at once (thesis: "more than one region per launch" on larger GPUs).
    int64_t thesis_regions_per_launch() const {
        const int64_t resident = int64_t(sms_) * max_threads_per_sm_;
        int64_t regions = std::max<int64_t>(1, resident / GridRegionPiece::kRegionPoints);
        const size_t per_region = size_t(GridRegionPiece::kRegionPoints) * (3 * sizeof(T) + 2 * sizeof(int) +
                                                                           DevicePieceResults::bytes_per_point());
        regions = std::min<int64_t>(regions, std::max<size_t>(1, budget_ / per_region));
        if (options_.max_points_per_piece > 0)
            regions = std::max<int64_t>(1, std::min<int64_t>(regions, options_.max_points_per_piece / GridRegionPiece::kRegionPoints));
        return regions;
    }

    double upload_seconds() const { return upload_.seconds(); }
    double kernel_seconds() const { return compute_.seconds(); }
    double download_seconds() const { return download_.seconds(); }
    nlohmann::json plan() const {
        return {{"pieces", pieces_},
                {"triangle_chunks", chunk_count()},
                {"triangles_per_chunk", chunk_size_},
                {"points_per_thread", points_per_thread_},
                {"triangle_splits", splits_}};
    }

private:
    // ---- tuned kernel ---------------------------------------------------------------
    void plan_triangle_chunks() {
        const size_t packed_bytes = size_t(num_triangles_) * sizeof(PackedTriangle<T>);
        chunk_size_ = num_triangles_;
        if (packed_bytes > budget_ / 2) chunk_size_ = int(budget_ / 2 / sizeof(PackedTriangle<T>));
        if (options_.max_triangles_per_chunk > 0) chunk_size_ = std::min(chunk_size_, options_.max_triangles_per_chunk);
        if (chunk_size_ < kTunedTile && chunk_size_ < num_triangles_)
            throw std::runtime_error("CUDA sampler (tuned): " + std::to_string(budget_ >> 20) +
                                     " MiB of free GPU memory cannot hold even one tile of " +
                                     std::to_string(kTunedTile) + " triangles");
        packed_.allocate(size_t(chunk_size_));
        if (chunk_size_ == num_triangles_) upload_chunk(0);  // resident: upload once
    }

    int chunk_count() const { return chunk_size_ > 0 ? (num_triangles_ + chunk_size_ - 1) / chunk_size_ : 0; }

    void upload_chunk(int chunk) {
        const int first = chunk * chunk_size_;
        const int count = std::min(chunk_size_, num_triangles_ - first);
        upload_.begin();
        packed_.upload(host_.packed.data() + first, size_t(count));
        upload_.end();
        resident_chunk_ = chunk;
    }

    int choose_points_per_thread(int64_t n) const {
        if (options_.points_per_thread > 0) return options_.points_per_thread;
        // As many points per thread as still give every SM a few blocks, counting the
        // triangle splits that multiply the blocks (more points per thread = fewer loads).
        const int64_t max_splits = std::clamp(std::min(chunk_size_, num_triangles_) / (4 * kTunedTile), 1, 64);
        for (int k : {8, 4, 2})
            if ((n + int64_t(kTunedThreads) * k - 1) / (int64_t(kTunedThreads) * k) * max_splits >= 4 * int64_t(sms_)) return k;
        return 1;
    }

    int choose_splits(int64_t n, int k) const {
        const int64_t point_blocks = (n + int64_t(kTunedThreads) * k - 1) / (int64_t(kTunedThreads) * k);
        const int64_t target_blocks = int64_t(sms_) * 16;
        const int max_by_triangles = std::max(1, std::min(chunk_size_, num_triangles_) / (4 * kTunedTile));
        return int(std::clamp<int64_t>((target_blocks + point_blocks - 1) / point_blocks, 1, std::min(64, max_by_triangles)));
    }

    int64_t tuned_piece_points(int64_t total) {
        points_per_thread_ = choose_points_per_thread(total);
        splits_ = choose_splits(total, points_per_thread_);
        const size_t per_point = (sizeof(T) + sizeof(int)) * size_t(1 + splits_) + DevicePieceResults::bytes_per_point();
        const size_t chunk_bytes = size_t(chunk_size_) * sizeof(PackedTriangle<T>);
        const size_t left = budget_ > chunk_bytes ? budget_ - chunk_bytes : 0;
        int64_t step = std::min<int64_t>(total, int64_t(left / per_point));
        if (options_.max_points_per_piece > 0) step = std::min(step, options_.max_points_per_piece);
        if (step < std::min<int64_t>(total, kTunedThreads))
            throw std::runtime_error("CUDA sampler (tuned): " + std::to_string(left >> 20) +
                                     " MiB of free GPU memory cannot hold one piece of " +
                                     std::to_string(kTunedThreads) + " points (" + std::to_string(per_point) +
                                     " bytes each)");
        return std::max<int64_t>(step, 1);
    }

    template <int K, typename Piece>
    void launch_tuned(const Piece& piece, int count, int offset, T* pq, int* pi, int splits) {
        const int64_t n = piece.size();
        const dim3 grid(unsigned((n + int64_t(kTunedThreads) * K - 1) / (int64_t(kTunedThreads) * K)), unsigned(splits));
        const int per_split = (count + splits - 1) / splits;
        nearest_triangle_tuned<T, K><<<grid, kTunedThreads>>>(piece, packed_.get(), count, offset, per_split, pq, pi);
        CUDA_CHECK_LAUNCH("nearest_triangle_tuned");
    }

    template <typename Piece>
    HostPieceResults tuned_piece(const Piece& piece) {
        const int64_t n = piece.size();
        DeviceBuffer<T> best_q{size_t(n)}, partial_q{size_t(n) * size_t(splits_)};
        DeviceBuffer<int> best_i{size_t(n)}, partial_i{size_t(n) * size_t(splits_)};
        DevicePieceResults out(n);
        for (int chunk = 0; chunk < chunk_count(); ++chunk) {
            if (chunk != resident_chunk_) upload_chunk(chunk);
            compute_.begin();
            if (chunk == 0) {
                fill_minima<<<blocks_for(n, kFinalizeThreads), kFinalizeThreads>>>(n, best_q.get(), best_i.get());
                CUDA_CHECK_LAUNCH("fill_minima");
            }
            const int first = chunk * chunk_size_;
            const int count = std::min(chunk_size_, num_triangles_ - first);
            switch (points_per_thread_) {
                case 8: launch_tuned<8>(piece, count, first, partial_q.get(), partial_i.get(), splits_); break;
                case 4: launch_tuned<4>(piece, count, first, partial_q.get(), partial_i.get(), splits_); break;
                case 2: launch_tuned<2>(piece, count, first, partial_q.get(), partial_i.get(), splits_); break;
                default: launch_tuned<1>(piece, count, first, partial_q.get(), partial_i.get(), splits_); break;
            }
            merge_partial_minima<<<blocks_for(n, kFinalizeThreads), kFinalizeThreads>>>(
                n, splits_, partial_q.get(), partial_i.get(), best_q.get(), best_i.get());
            CUDA_CHECK_LAUNCH("merge_partial_minima");
            compute_.end();
        }
        compute_.begin();
        if (certifier_) certifier_->certify(piece, point_coordinate_, best_i.get());
        launch_finalize_samples(n, mesh_.view(), piece, best_i.get(),
                                winding_.view(), options_.band_width, out.outputs());
        CUDA_CHECK_LAUNCH("finalize_samples");
        compute_.end();
        download_.begin();
        HostPieceResults h = out.download(n);
        download_.end();
        return h;
    }

    // ---- thesis kernel --------------------------------------------------------------
    void prepare_thesis_chunks() {
        chunk_size_ = thesis_chunk_triangles<T>();
        if (options_.max_triangles_per_chunk > 0) chunk_size_ = std::min(chunk_size_, options_.max_triangles_per_chunk);
        // Triangles as the thesis sent them: three vertices, 9 scalars, in mesh order.
        thesis_triangles_.resize(size_t(num_triangles_) * 9);
        for (int i = 0; i < num_triangles_; ++i)
            for (int k = 0; k < 3; ++k) {
                const Vec3<T>& v = host_.vertices[size_t(host_.triangles[size_t(i)][k])];
                thesis_triangles_[size_t(i) * 9 + size_t(3 * k) + 0] = v.x;
                thesis_triangles_[size_t(i) * 9 + size_t(3 * k) + 1] = v.y;
                thesis_triangles_[size_t(i) * 9 + size_t(3 * k) + 2] = v.z;
            }
    }

    template <typename Piece>
    HostPieceResults thesis_piece(const Piece& piece) {
        const int64_t n = piece.size();
        DeviceBuffer<T> d2{size_t(n)}, s{size_t(n)}, t{size_t(n)};
        DeviceBuffer<int> tri{size_t(n)}, feature{size_t(n)};
        const ThesisMinima<T> minima{d2.get(), tri.get(), s.get(), t.get(), feature.get()};
        DevicePieceResults out(n);
        compute_.begin();
        fill_thesis_minima<<<blocks_for(n, kFinalizeThreads), kFinalizeThreads>>>(n, minima);
        CUDA_CHECK_LAUNCH("fill_thesis_minima");
        // All triangles for this piece of the lattice before moving on (thesis section 3.3).
        for (int first = 0; first < num_triangles_; first += chunk_size_) {
            const int count = std::min(chunk_size_, num_triangles_ - first);
            CUDA_CHECK(cudaMemcpyToSymbolAsync(c_thesis_chunk, thesis_triangles_.data() + size_t(first) * 9,
                                               size_t(count) * 9 * sizeof(T), 0, cudaMemcpyHostToDevice));
            nearest_triangle_thesis<T><<<blocks_for(n, kThesisThreads), kThesisThreads>>>(piece, first, count, minima);
            CUDA_CHECK_LAUNCH("nearest_triangle_thesis");
        }
        if (winding_.view().enabled())
            finalize_thesis_samples<T, true><<<blocks_for(n, kFinalizeThreads), kFinalizeThreads>>>(mesh_.view(), piece, minima,
                                                                                                  winding_.view(), options_.band_width, out.outputs());
        else
            finalize_thesis_samples<T, false><<<blocks_for(n, kFinalizeThreads), kFinalizeThreads>>>(mesh_.view(), piece, minima,
                                                                                                   winding_.view(), options_.band_width, out.outputs());
        CUDA_CHECK_LAUNCH("finalize_thesis_samples");
        compute_.end();
        download_.begin();
        HostPieceResults h = out.download(n);
        download_.end();
        return h;
    }

    const MeshBuffers<T>& host_;          ///< search data in precision T
    SamplerOptions options_;
    CudaKernel kernel_;
    const DeviceMesh<double>& mesh_;      ///< for the final evaluation
    const DeviceWinding& winding_;
    DeviceBuffer<PackedTriangle<T>> packed_;
    std::vector<T> thesis_triangles_;
    EventTimer upload_, compute_, download_;
    int sms_ = 1, max_threads_per_sm_ = 1024;
    const DeviceCertifier* certifier_ = nullptr;
    double point_coordinate_ = 0;
    size_t budget_ = 0;
    int num_triangles_ = 0, chunk_size_ = 0, resident_chunk_ = -1;
    int points_per_thread_ = 0, splits_ = 1;
    int64_t pieces_ = 0;
};

class BoundCudaBruteForce final : public BackendSampler {
public:
    /// Uploads the double mesh and, in winding mode, the sign's moments; the tuned float
    /// search's certificate is built over the mesh's BVH (certify_kernel.cuh). The packed
    /// triangles of the search are planned per call against the GPU memory free then.
    BoundCudaBruteForce(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, CudaKernel kernel)
        : BackendSampler(std::move(mesh), options, "cuda", "brute_force", kernel_name(kCudaBruteForceKernels, kernel)),
          kernel_(kernel) {
        sign_.prepare(this->mesh());
        const DeviceGuard on_device(options.device);
        device_mesh_ = std::make_unique<DeviceMesh<double>>(this->mesh().buffers<double>());
        winding_.upload(sign_, device_mesh_->view());
        // The thesis's kernel stays as the thesis wrote it (uncertified), double is the reference.
        if (float_search() && kernel_ == CudaKernel::Tuned)
            certifier_ = std::make_unique<DeviceCertifier>(*this->mesh().bvh(), this->mesh());
    }

private:
    SampledField sample_blocks(SlabRun& run) const override {
        const std::lock_guard<std::mutex> lock(mutex_);  // the certifier's counters
        const DeviceGuard on_device(options_.device);
        return with_precision(options_.precision, [&](auto zero) { return sample_as<decltype(zero)>(run); });
    }

    std::vector<PointSample> query_points(const std::vector<Vec3d>& points, SamplingTimings&,
                                          CertificateCounters& certificate) const override {
        const std::lock_guard<std::mutex> lock(mutex_);
        const DeviceGuard on_device(options_.device);
        return with_precision(options_.precision, [&](auto zero) { return query_as<decltype(zero)>(points, certificate); });
    }

    /// The certifier reset for a run over points of largest |coordinate| `point_coordinate`.
    template <typename T>
    const DeviceCertifier* certifier_for(double point_coordinate, Engine<T>& engine) const {
        if (!certifier_) return nullptr;
        certifier_->reset();
        engine.certify_with(certifier_.get(), point_coordinate);
        return certifier_.get();
    }

    template <typename T>
    SampledField sample_as(SlabRun& run) const {
        const Lattice& lattice = run.lattice;
        SampledField field = unfilled_field(mesh(), lattice, run.slab, options_.precision);
        Engine<T> engine(mesh(), options_, kernel_, *device_mesh_, winding_);
        const DeviceCertifier* certifier = certifier_for<T>(largest_lattice_coordinate(lattice), engine);
        winding_.reset_counts();
        auto sink = [&](const HostPieceResults& h) { scatter_batch(h, mesh(), field); };
        for (const GridBlock& block : run) {
            if (kernel_ == CudaKernel::Tuned) {
                engine.run_tuned(block.count(), [&](int64_t begin, int64_t count) {
                    return GridRangePiece{lattice, block, begin, count};
                }, sink);
                run.computed += block.count();
            } else {
                GridRegionPiece piece{lattice, block, {}, 0, 0};
                const int r = GridRegionPiece::kRegion;
                piece.regions = {(block.resolution.x + r - 1) / r, (block.resolution.y + r - 1) / r,
                                 (block.resolution.z + r - 1) / r};
                const int64_t regions = int64_t(piece.regions.x) * piece.regions.y * piece.regions.z;
                const int64_t per_launch = engine.thesis_regions_per_launch();
                for (int64_t first = 0; first < regions; first += per_launch) {
                    piece.first_region = first;
                    piece.region_count = std::min(per_launch, regions - first);
                    engine.run_thesis(piece, sink);
                }
                // Padding threads do the work too (thesis: "a few threads that are not performing necessary work").
                run.computed += regions * GridRegionPiece::kRegionPoints;
            }
        }
        run.device.upload = engine.upload_seconds();
        run.device.kernel = engine.kernel_seconds();
        run.device.download = engine.download_seconds();
        run.details["plan"] = engine.plan();
        run.details["device"] = describe_device(options_.device);
        if (certifier) certifier->read(run.certificate);
        winding_.read_counts(run.winding);
        run.certified = certifier != nullptr;
        return field;
    }

    template <typename T>
    std::vector<PointSample> query_as(const std::vector<Vec3d>& points, CertificateCounters& certificate) const {
        std::vector<PointSample> out(points.size());
        Engine<T> engine(mesh(), options_, kernel_, *device_mesh_, winding_);
        const DeviceCertifier* certifier = certifier_for<T>(largest_coordinate(points), engine);
        DeviceBuffer<Vec3d> device_points;
        device_points.upload(points);
        auto sink = [&](const HostPieceResults& h) { scatter_batch(h, mesh(), out); };
        const int64_t n = int64_t(points.size());
        if (kernel_ == CudaKernel::Tuned) {
            engine.run_tuned(n, [&](int64_t begin, int64_t count) { return PointListPiece{device_points.get(), begin, count}; },
                             sink);
        } else {
            const int64_t step = engine.thesis_regions_per_launch() * GridRegionPiece::kRegionPoints;
            for (int64_t begin = 0; begin < n; begin += step)
                engine.run_thesis(PointListPiece{device_points.get(), begin, std::min(step, n - begin)}, sink);
        }
        if (certifier) certifier->read(certificate);
        return out;
    }

    CudaKernel kernel_;
    std::unique_ptr<DeviceMesh<double>> device_mesh_;
    DeviceWinding winding_;
    std::unique_ptr<DeviceCertifier> certifier_;  ///< float "tuned" only
    mutable std::mutex mutex_;                    ///< calls share the certifier's and the winding sign's device counters
};

}  // namespace

std::unique_ptr<Sampler> make_cuda_brute_force_sampler(const SamplerOptions& options) {
    return std::make_unique<BackendFactory<BoundCudaBruteForce, CudaKernel>>(options, "cuda", "brute_force",
                                                                             kCudaBruteForceKernels, "CUDA brute-force");
}

}  // namespace sdf::cuda
