// The CUDA BVH sampler's lattices: cuts a slab into pieces of z-layers that fit GPU memory,
// runs the BVH search and the double-precision finalize on each, and scatters the results
// (or, for the streamed writer, stores them on the device in the field file's bytes:
// stored_output.cuh). Its tree is made at binding (bvh_device_tree.cu), its point lists
// are bvh_point_query.cu's.
#include "cuda/bvh/bvh_sampler.h"

#include <algorithm>
#include <future>
#include <stdexcept>
#include <string>

#include "core/sampling/sampler_results.h"
#include "cuda/bvh/bvh_bound_sampler.cuh"
#include "cuda/bvh/bvh_candidates_kernel.cuh"
#include "cuda/bvh/bvh_warp_kernel.cuh"
#include "cuda/util/cuda_check.h"
#include "cuda/util/cuda_device.h"

namespace sdf::cuda {

/// z-layers per slab: as many as 80% of free GPU memory holds (and max_points_per_piece).
int BoundCudaBvh::layers_per_slab(const GridBlock& block) const {
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
BandSearch BoundCudaBvh::band_search(const DeviceBvh<T>& dev) const {
    const bool winding = dev.winding.view().enabled();
    const FloatSearchBound& bound = mesh().search_bound();
    const double reach = std::is_same_v<T, float> ? bound.sliver_reach_float : bound.sliver_reach_double;
    return {options_.band_width, dev.mesh->view(), winding, winding || solid(), reach, double_view(dev, bound)};
}

template <typename T>
void BoundCudaBvh::launch_slab(const DeviceBvh<T>& dev, const GridRangePiece& piece, const SlabGeometry& slab,
                               const StreamedCertify& cert, int* nearest) const {
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
            launch_bvh_warp(view, SlabLayout{piece, slab}, band_search(dev), cert, nearest, {}, warp_queue());
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
void BoundCudaBvh::run_slab(const DeviceBvh<T>& dev, const Lattice& lattice, const GridBlock& block, int z0, int nz,
                            EventTimer& compute, Sink sink) const {
    const int64_t layer = int64_t(block.resolution.x) * block.resolution.y;
    const GridRangePiece piece{lattice, block, z0 * layer, nz * layer};
    const SlabGeometry slab{block.resolution, z0, nz};
    PieceResults r(piece.count);
    compute.begin();
    const double coordinate = largest_lattice_coordinate(lattice);
    const StreamedCertify fused = streamed_certify(dev, kernel_, coordinate);
    launch_slab<T>(dev, piece, slab, fused, r.nearest.get());
    if (!fused.exact) certify(dev, piece, coordinate, r.nearest.get());
    launch_finalize_samples(piece.count, dev.mesh->view(), piece, r.nearest.get(), dev.winding.view(), options_.band_width,
                            r.outputs());
    CUDA_CHECK_LAUNCH("finalize_samples (bvh slab)");
    compute.end();
    sink(r, piece.count);
}

/// Runs every piece of the slab's blocks through run_slab, counting the points computed;
/// returns the pieces (GPU memory decides how many z-layers a piece holds).
template <typename T, typename Sink>
int64_t BoundCudaBvh::run_blocks(const DeviceBvh<T>& dev, SlabRun& run, EventTimer& compute, Sink sink) const {
    int64_t pieces = 0;
    reset_certificate(dev);
    dev.winding.reset_counts();
    if (kernel_ == BvhGpuKernel::Candidates)
        CUDA_CHECK(cudaMemset(candidate_stats_.get(), 0, 4 * sizeof(unsigned long long)));
    for (const GridBlock& block : run) {
        const int layers = layers_per_slab(block);
        for (int z0 = 0; z0 < block.resolution.z; z0 += layers, ++pieces)
            run_slab<T>(dev, run.lattice, block, z0, std::min(layers, block.resolution.z - z0), compute, sink);
        run.computed += block.count();
    }
    return pieces;
}

template <typename T, typename F>
int64_t BoundCudaBvh::store_blocks(const DeviceBvh<T>& dev, SlabRun& run, const StoredChannels<F>& out,
                                   EventTimer& compute) const {
    auto sink = [&](const PieceResults& r, int64_t count) {
        compute.begin();
        store_piece<F><<<blocks_for(count, 256), 256>>>(r.outputs(), count, out);
        CUDA_CHECK_LAUNCH("store_piece");
        compute.end();
    };
    return run_blocks<T>(dev, run, compute, sink);
}

template <typename T>
void BoundCudaBvh::record_run(SlabRun& run, const DeviceBvh<T>& dev, const EventTimer& upload, const EventTimer& compute,
                              const EventTimer& download, int64_t pieces) const {
    run.device.upload = upload.seconds();
    run.device.kernel = compute.seconds();
    run.device.download = download.seconds();
    nlohmann::json bvh_info = bvh_stats_;
    bvh_info["built_by_bind"] = built_;
    run.details["plan"] = {{"pieces", pieces}, {"threads_per_block", kBvhThreads}, {"points_per_thread", kRunPoints}};
    run.details["bvh"] = bvh_info;
    run.details["device"] = describe_device(options_.device);
    if (kernel_ == BvhGpuKernel::Candidates) {
        unsigned long long counts[4] = {0, 0, 0, 0};
        candidate_stats_.download(counts, 4);
        CUDA_CHECK(cudaStreamSynchronize(0));
        const double bricks = double(counts[0]);
        run.details["candidates"] = {{"bricks_searched", counts[0]},
                                     {"bricks_outside_band", counts[2]},
                                     {"mean_candidate_triangles", bricks > 0 ? double(counts[1]) / bricks : 0.0},
                                     {"mean_leaf_ranges", bricks > 0 ? double(counts[3]) / bricks : 0.0},
                                     {"points_per_brick", 32 * kRunPoints}};
    }
    // The float search's certificate (certify_kernel.cuh); double searches are the reference.
    read_certificate(dev, run.certificate);
    dev.winding.read_counts(run.winding);  // the certified winding sign's, beside the search's
    run.band_skips = (kernel_ == BvhGpuKernel::Warp || kernel_ == BvhGpuKernel::Candidates) && band_skips_possible();
}

SampledField BoundCudaBvh::sample_blocks(SlabRun& run) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    const DeviceGuard on_device(options_.device);
    return with_precision(options_.precision, [&](auto zero) { return sample_as<decltype(zero)>(run); });
}

template <typename T>
SampledField BoundCudaBvh::sample_as(SlabRun& run) const {
    const DeviceBvh<T>& dev = tree<T>();
    const Lattice& lattice = run.lattice;
    EventTimer upload, compute, download;
    require_search_range(mesh(), lattice, options_.precision);
    // Results made on the device in the field's own layout (the stored path with float64
    // channels, stored_output.cuh) and copied once through pinned buffers straight into the
    // field's arrays: no per-piece pageable copy, no host scatter. A slab whose channels do
    // not fit half the free device memory (the other half for the pieces' buffers, and for
    // whatever else shares the device) takes the per-piece path below. A quarter sent a CC
    // 1024^3 field (36 GiB of channels) on one H200 to that path: 23.8 s of transfers, against
    // 0.8 s for the same field split over two H200s, whose halves fitted.
    const int64_t points = slab_point_count(lattice, run.slab);
    const StoredLayout layout{false, true, true};
    const size_t free_bytes = free_device_memory();
    if (points > 0 && double(points) * double(layout.bytes_per_point()) <= 0.5 * double(free_bytes)) {
        // The field's host arrays (each page mapped at its first write) are made on other
        // threads while the device computes.
        std::future<SampledField> made =
            std::async(std::launch::async, [&] { return unfilled_field(mesh(), lattice, run.slab, options_.precision); });
        const StoredChannels<double> out = stored_buffers_.device_channels<double>(points, layout, dev.source_triangle.get());
        const int64_t pieces = store_blocks<T, double>(dev, run, out, compute);
        SampledField field = made.get();
        download.begin();
        const size_t n = size_t(points);
        staged_.to_host(out.distance, field.distance.data(), n * sizeof(double));
        staged_.to_host(out.gradient, field.gradient.data(), 3 * n * sizeof(double));
        staged_.to_host(out.triangle, field.closest_triangle.data(), n * sizeof(int32_t));
        download.end();
        record_run(run, dev, upload, compute, download, pieces);
        return field;
    }
    SampledField field = unfilled_field(mesh(), lattice, run.slab, options_.precision);
    auto sink = [&](const PieceResults& r, int64_t count) {
        download.begin();
        const HostPieceResults h = r.download(count);
        download.end();
        scatter_batch(h, mesh(), field);
    };
    const int64_t pieces = run_blocks<T>(dev, run, compute, sink);
    record_run(run, dev, upload, compute, download, pieces);
    return field;
}

/// sample_slab() with the results stored on the device in the field file's bytes
/// (stored_output.cuh) and brought to the host in one pinned copy.
std::optional<StoredSlab> BoundCudaBvh::sample_slab_stored(const Lattice& lattice, const LatticeSlab& slab,
                                                           const StoredLayout& layout) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    const DeviceGuard on_device(options_.device);
    SlabRun run(lattice, slab, options_.bcc_strategy);
    StoredSlab stored = with_precision(options_.precision, [&](auto zero) { return sample_stored_as<decltype(zero)>(run, layout); });
    finish_slab(stored.info, run, stored.band);
    stored.info.sampler.details["stored_on_device"] = true;
    return stored;
}

template <typename T>
StoredSlab BoundCudaBvh::sample_stored_as(SlabRun& run, const StoredLayout& layout) const {
    const DeviceBvh<T>& dev = tree<T>();
    EventTimer upload, compute, download;
    StoredSlab stored;
    require_search_range(mesh(), run.lattice, options_.precision);
    stored.info.lattice = run.lattice;
    stored.info.precision = options_.precision;
    const int64_t points = slab_point_count(run.lattice, run.slab);
    const int32_t* source = dev.source_triangle.get();
    const int64_t pieces =
        layout.float32 ? store_blocks<T, float>(dev, run, stored_buffers_.device_channels<float>(points, layout, source), compute)
                       : store_blocks<T, double>(dev, run, stored_buffers_.device_channels<double>(points, layout, source), compute);
    download.begin();
    stored_buffers_.download(points, layout, stored);
    download.end();
    record_run(run, dev, upload, compute, download, pieces);
    return stored;
}

std::unique_ptr<Sampler> make_cuda_bvh_sampler(const SamplerOptions& options) {
    return std::make_unique<BackendFactory<BoundCudaBvh, BvhGpuKernel>>(options, "cuda", "bvh", kCudaBvhKernels, "CUDA BVH");
}

}  // namespace sdf::cuda
