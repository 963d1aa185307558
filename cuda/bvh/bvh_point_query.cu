// The CUDA BVH sampler's point lists (cuda/bvh/bvh_sampler.h): the points sorted into Morton
// order on the device, searched 128 at a time by the warp kernels and finalized, every
// result written back at its input position; from host vectors, from the caller's device
// arrays (core/sampling/device_query.h) or from its host arrays through pinned buffers
// (core/sampling/host_query.h).
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <future>
#include <optional>
#include <stdexcept>
#include <string>

#include <cub/device/device_radix_sort.cuh>

#include "core/sampling/search_range.h"
#include "cuda/bvh/bvh_bound_sampler.cuh"
#include "cuda/bvh/bvh_candidates_kernel.cuh"
#include "cuda/bvh/bvh_warp_kernel.cuh"
#include "cuda/util/cuda_check.h"
#include "cuda/sampling/device_points.cuh"
#include "kernels/core/morton.h"

namespace sdf::cuda {
namespace {

/// The bits of the 63-bit Morton key the point lists are sorted by: the top 10 of each axis
/// (1024^3 cells of the mesh's box; points of one cell keep their input order). The order
/// only groups neighbours into warps, and 30 bits take CUB 4 radix passes where 63 take 8:
/// the query's kernels 2% faster at 1M and 16.8M points on an H200, the same bits
/// (docs/gpu-notes.md); 24 and 27 bits (3 or 4 passes of 32-bit keys) measured the same
/// as 30 at both sizes.
constexpr int kSortBits = 30;

/// The sort key of each point (the top kSortBits of its 63-bit Morton key) and its position.
template <typename Key, typename Index>
__global__ void morton_keys(const Vec3d* points, int64_t n, Vec3d lo, double inv_side, Key* keys, Index* identity) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const Vec3d p = points[i];
    keys[i] = Key(morton_key_of_point(p.x, p.y, p.z, lo.x, lo.y, lo.z, inv_side) >> (63 - kSortBits));
    identity[i] = Index(i);
}

/// sorted[i] = the point at input position order[i]; where asked, order[i] widened into
/// `wide_order`, and rank[order[i]] = i (the ranks' scatter).
template <typename Index>
__global__ void gather_points(const Vec3d* points, const Index* order, int64_t n, Vec3d* sorted, int64_t* wide_order,
                              int32_t* rank) {
    const int64_t i = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= n) return;
    const int64_t o = order[i];
    sorted[i] = points[o];
    if (wide_order != nullptr) wide_order[i] = o;
    if (rank != nullptr) rank[o] = int32_t(i);
}

/// Points per thread of the warp search over `n` listed points on a GPU of `sms`
/// multiprocessors: 2 where the list fills the GPU's resident warps 32 times over at 2, else
/// 1. With the resident warps taking batches from a counter (WarpBatches), measured on an H200
/// (docs/gpu-notes.md): 1M points near the surface 3.47 ms at 1, 4.04 at 2, 5.43 at 4; 16.8M
/// points 26.6, 25.4, 28.8 ms (uniform 32.9, 30.8, 34.0). SDF_LIST_RUN (1, 2 or 4) overrides
/// the rule, for measurement.
int list_points_per_thread(int64_t n, int sms) {
    static const int forced = [] {
        const char* e = std::getenv("SDF_LIST_RUN");
        const int v = e ? std::atoi(e) : 0;
        return v == 1 || v == 2 || v == 4 ? v : 0;
    }();
    if (forced) return forced;
    const int64_t resident_warps = int64_t(sms) * kFusedMinBlocks * (kBvhThreads / 32);
    return n / (32 * 2) >= 32 * resident_warps ? 2 : 1;
}

/// Whether each lane's search of a point list is seeded by its own descent
/// (ListRuns::seeded); SDF_LIST_SEED=off walks unseeded, for measurement.
bool list_seeded() {
    static const bool off = [] {
        const char* e = std::getenv("SDF_LIST_SEED");
        return e != nullptr && std::strcmp(e, "off") == 0;
    }();
    return !off;
}

/// Whether the point lists' certified search lists its candidates for a re-rank after the
/// walk (and the winding sign's nearest_side) instead of streaming them in double during it.
/// SDF_LIST_CERTIFY=streamed keeps the streamed form, for measurement.
bool list_certificate_candidates() {
    static const bool streamed = [] {
        const char* e = std::getenv("SDF_LIST_CERTIFY");
        return e != nullptr && std::strcmp(e, "streamed") == 0;
    }();
    return !streamed;
}

/// Entries of each point's NearLists: kNearListSlots, or SDF_NEAR_LIST_SLOTS (2 to 64), for
/// measurement.
int near_list_slots() {
    static const int slots = [] {
        const char* e = std::getenv("SDF_NEAR_LIST_SLOTS");
        const int v = e ? std::atoi(e) : 0;
        return v >= 2 && v <= 64 ? v : kNearListSlots;
    }();
    return slots;
}

/// Device arrays of NearLists for `n` points, and of the sides nearest_side() finds from
/// them where `sides` (the certified winding sign with its table of sides).
struct NearListBuffers {
    int slots;
    DeviceBuffer<int32_t> slot, count;
    DeviceBuffer<float> q, best_q;
    DeviceBuffer<int8_t> side;
    /// Bytes per point: the slots and their Q, the count, the winner's Q, the side.
    static size_t bytes_per_point(int slots) { return size_t(slots) * (sizeof(int32_t) + sizeof(float)) + 2 * 4 + 1; }
    NearListBuffers(int64_t n, int entries, bool sides)
        : slots(entries), slot{size_t(n) * size_t(entries)}, count{size_t(n)}, q{size_t(n) * size_t(entries)}, best_q{size_t(n)} {
        if (sides) side.allocate(size_t(n));
    }
    NearLists view() { return {slot.get(), q.get(), count.get(), best_q.get(), slots, int64_t(count.size())}; }
};

/// The current device's multiprocessors.
int multiprocessors() {
    int device = 0, sms = 1;
    CUDA_CHECK(cudaGetDevice(&device));
    CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
    return sms;
}

/// Whether the ranks (each input position's place in sorted order) come from a second
/// radix sort (of the sorted order, by position) rather than a scatter: for lists of at
/// least kRankSortPoints points, where the scatter's 4-byte writes miss the L2 cache. On an
/// H200, 16.8M points near the surface: 18.46 ms by sort, 19.24 by scatter; 1M: 3.00 and
/// 2.97 (docs/gpu-notes.md). SDF_RANK_BY=scatter or sort overrides the rule, for measurement.
constexpr int64_t kRankSortPoints = int64_t(1) << 22;
bool ranks_by_sort(int64_t n) {
    static const int forced = [] {
        const char* e = std::getenv("SDF_RANK_BY");
        return e == nullptr ? 0 : std::strcmp(e, "sort") == 0 ? 1 : std::strcmp(e, "scatter") == 0 ? 2 : 0;
    }();
    return forced ? forced == 1 : n >= kRankSortPoints;
}

/// The least b with 2^b >= n: the bits that hold every value below n.
int bits_below(int64_t n) {
    int b = 1;
    while (b < 63 && (int64_t(1) << b) < n) ++b;
    return b;
}

/// Sorts points by their Morton keys in the mesh's (cubic) box; the buffers (keys, CUB's
/// temporary storage) are allocated by the constructor. Lists of at most INT32_MAX points
/// sort 32-bit keys and positions (half the bytes a pass moves); longer ones 64-bit.
struct MortonSort {
    int64_t n;
    bool narrow;  ///< 32-bit keys and positions
    DeviceBuffer<uint32_t> keys32, keys32_sorted;
    DeviceBuffer<int32_t> identity32, order32;
    DeviceBuffer<uint64_t> keys64, keys64_sorted;
    DeviceBuffer<int64_t> identity64;
    DeviceBuffer<unsigned char> temp;
    size_t temp_bytes = 0;

    explicit MortonSort(int64_t count) : n(count), narrow(count <= int64_t(INT32_MAX)) {
        if (narrow) {
            keys32.allocate(size_t(n));
            keys32_sorted.allocate(size_t(n));
            identity32.allocate(size_t(n));
            order32.allocate(size_t(n));
            size_t by_key = 0, by_position = 0;
            CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, by_key, keys32.get(), keys32_sorted.get(), identity32.get(),
                                                       order32.get(), n, 0, kSortBits));
            CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, by_position, keys32.get(), keys32_sorted.get(),
                                                       identity32.get(), order32.get(), n, 0, bits_below(n)));
            temp_bytes = std::max(by_key, by_position);
        } else {
            keys64.allocate(size_t(n));
            keys64_sorted.allocate(size_t(n));
            identity64.allocate(size_t(n));
            CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, keys64.get(), keys64_sorted.get(),
                                                       identity64.get(), identity64.get(), n, 0, kSortBits));
        }
        temp.allocate(temp_bytes);
    }

    /// `sorted` receives the points in key order, `order` (or null) their input positions
    /// and `rank` (or null; narrow lists only) the inverse: each input position's place in
    /// key order.
    void run(const PreparedMesh& mesh, const Vec3d* points, Vec3d* sorted, int64_t* order, int32_t* rank) {
        const Bounds3& box = mesh.bounds();
        const Vec3d extent = box.extent();
        const double side = std::max({extent.x, extent.y, extent.z, 1e-300});
        const int blocks = blocks_for(n, 256);
        if (!narrow) {
            if (order == nullptr || rank != nullptr) throw std::logic_error("MortonSort: a list this long sorts into `order` only");
            morton_keys<<<blocks, 256>>>(points, n, box.min, 1.0 / side, keys64.get(), identity64.get());
            CUDA_CHECK_LAUNCH("morton_keys");
            size_t bytes = temp_bytes;
            CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp.get(), bytes, keys64.get(), keys64_sorted.get(),
                                                       identity64.get(), order, n, 0, kSortBits));
            gather_points<<<blocks, 256>>>(points, order, n, sorted, static_cast<int64_t*>(nullptr), nullptr);
            CUDA_CHECK_LAUNCH("gather_points");
            return;
        }
        morton_keys<<<blocks, 256>>>(points, n, box.min, 1.0 / side, keys32.get(), identity32.get());
        CUDA_CHECK_LAUNCH("morton_keys");
        size_t bytes = temp_bytes;
        CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp.get(), bytes, keys32.get(), keys32_sorted.get(), identity32.get(),
                                                   order32.get(), n, 0, kSortBits));
        const bool rank_by_sort = rank != nullptr && ranks_by_sort(n);
        gather_points<<<blocks, 256>>>(points, order32.get(), n, sorted, order, rank_by_sort ? nullptr : rank);
        CUDA_CHECK_LAUNCH("gather_points");
        if (rank_by_sort) {
            // Sorting the positions (a permutation of 0..n-1) carries each sorted place along;
            // identity32 still holds 0..n-1 (CUB's pointer form leaves its inputs as they are).
            bytes = temp_bytes;
            CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp.get(), bytes, reinterpret_cast<const uint32_t*>(order32.get()),
                                                       keys32_sorted.get(), identity32.get(), rank, n, 0, bits_below(n)));
        }
    }
};

/// `buffer` with room for `count` elements (kept between queries: a bound SDF queried many
/// times allocates once).
template <typename E>
E* grow(DeviceBuffer<E>& buffer, size_t count) {
    if (buffer.size() < count) buffer.allocate(count);
    return buffer.get();
}

}  // namespace

std::vector<PointSample> BoundCudaBvh::query_points(const std::vector<Vec3d>& points, SamplingTimings& timings,
                                                    CertificateCounters& certificate) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    const DeviceGuard on_device(options_.device);
    return with_precision(options_.precision,
                          [&](auto zero) { return query_as<decltype(zero)>(points, timings, certificate); });
}

bool BoundCudaBvh::query_device(const DevicePoints& points, const DeviceQueryResults& results, SamplingTimings* timings) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    SamplingTimings t;
    query_device_locked(points, results, t);
    if (timings) *timings = t;
    return true;
}

void BoundCudaBvh::query_device_locked(const DevicePoints& points, const DeviceQueryResults& results,
                                       SamplingTimings& timings) const {
    if (points.device != options_.device)
        throw std::invalid_argument("CUDA BVH sampler: the points are on CUDA device " + std::to_string(points.device) +
                                    ", the sampler on device " + std::to_string(options_.device));
    if (points.count < 0 || (points.count > 0 && points.xyz == nullptr))
        throw std::invalid_argument("CUDA BVH sampler: no device points (count " + std::to_string(points.count) + ")");
    if (points.count == 0) return;
    const DeviceGuard on_device(options_.device);
    with_precision(options_.precision, [&](auto zero) { query_device_as<decltype(zero)>(points, results, timings); });
}

void BoundCudaBvh::query_host(const HostPoints& points, const HostQueryResults& results, SamplingTimings* timings) const {
    if (points.count <= 0) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto start = std::chrono::steady_clock::now();
    require_finite_points(points, "points", options_.threads);
    const DeviceGuard current(options_.device);
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
    SamplingTimings t;
    {
        // The caller's result arrays are mapped on other threads while the device searches.
        std::future<void> mapped = std::async(std::launch::async, [&] {
            if (results.distance) StagedCopy::map_pages(results.distance, n * sizeof(double));
            if (results.gradient) StagedCopy::map_pages(results.gradient, 3 * n * sizeof(double));
            if (results.triangle) StagedCopy::map_pages(results.triangle, n * sizeof(int32_t));
        });
        query_device_locked(on_device, columns, t);
        mapped.get();
    }
    const auto searched = std::chrono::steady_clock::now();
    if (results.distance) staged_.to_host(columns.distance, results.distance, n * sizeof(double));
    if (results.gradient) staged_.to_host(columns.gradient, results.gradient, 3 * n * sizeof(double));
    if (results.triangle) staged_.to_host(columns.triangle, results.triangle, n * sizeof(int32_t));
    const auto end = std::chrono::steady_clock::now();
    using seconds = std::chrono::duration<double>;
    t.upload += seconds(uploaded - start).count();
    t.download = seconds(end - searched).count();
    t.total = seconds(end - start).count();
    if (timings) *timings = t;
}

/// Point lists: Morton keys in the mesh's box, a device radix sort, then the warp search
/// over 128 consecutive sorted points (neighbours in space) and the finalize, whose
/// output_index sends every result back to its input position.
template <typename T>
std::vector<PointSample> BoundCudaBvh::query_as(const std::vector<Vec3d>& points, SamplingTimings& timings,
                                                CertificateCounters& certificate) const {
    // The vector first, pageable copies: making it on another thread while the device
    // works measured 2.5-3x slower (16.8M points, H200: 0.30-0.39 against 0.11-0.13 s),
    // with staged (pinned) copies too (0.37 against 0.17 s), and a new sampler's pinned
    // buffers cost a one-point query 15 ms (docs/gpu-notes.md).
    std::vector<PointSample> out(points.size());
    const DeviceBvh<T>& dev = tree<T>();
    EventTimer upload, compute, download;
    const auto start = std::chrono::steady_clock::now();
    const int64_t n = int64_t(points.size());
    DeviceBuffer<Vec3d> device_points{size_t(n)};
    upload.begin();
    device_points.upload(points);
    upload.end();
    DeviceBuffer<PointSample> device_out{size_t(n)};
    const double coordinate = largest_coordinate(points);
    search_points<T>(dev, device_points.get(), n, coordinate, compute, certificate,
                     [&](const PieceResults& r, int64_t count, const ResultOrder& order) {
        store_point_samples<<<blocks_for(count, 256), 256>>>(r.outputs(), count, order, dev.source_triangle.get(), device_out.get());
        CUDA_CHECK_LAUNCH("store_point_samples");
    });
    // The results are in input order on the device already: one copy, no host scatter.
    download.begin();
    device_out.download(out.data(), out.size());
    download.end();
    timings.upload = upload.seconds();
    timings.kernel = compute.seconds();
    timings.download = download.seconds();
    timings.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

/// query_as() for points already on the device, results written to the caller's device
/// arrays (core/sampling/device_query.h); no host copy of either.
template <typename T>
void BoundCudaBvh::query_device_as(const DevicePoints& points, const DeviceQueryResults& results,
                                   SamplingTimings& timings) const {
    require_search_range(mesh(), options_.precision);
    const DeviceBvh<T>& dev = tree<T>();
    EventTimer compute;
    const auto start = std::chrono::steady_clock::now();
    const int64_t n = points.count;
    // Work already queued on the caller's stream (that made the points) comes first.
    CUDA_CHECK(cudaStreamSynchronize(static_cast<cudaStream_t>(points.stream)));
    DeviceBuffer<Vec3d> device_points{size_t(n)};
    const double coordinate = read_points(points, device_points.get());
    CertificateCounters certificate;
    search_points<T>(dev, device_points.get(), n, coordinate, compute, certificate,
                     [&](const PieceResults& r, int64_t count, const ResultOrder& order) {
        store_point_columns<<<blocks_for(count, 256), 256>>>(r.outputs(), count, order, dev.source_triangle.get(), results);
        CUDA_CHECK_LAUNCH("store_point_columns");
    });
    CUDA_CHECK(cudaStreamSynchronize(0));
    timings = {};
    timings.kernel = compute.seconds();
    timings.point_triangle_pairs = double(n) * double(mesh().triangles().size());
    timings.total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    record_certificate(timings, certificate);
}

/// The caller's points as doubles in `out`, refused (naming the first) where a point is
/// not finite or beyond the search's range: only that point is copied to the host.
/// Returns their largest |coordinate| (the certified search's bound needs it).
double BoundCudaBvh::read_points(const DevicePoints& points, Vec3d* out) const {
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
/// piece; `store(results, count, order)` takes each piece's results to their input positions
/// (ResultOrder: gathered where the list is one piece), and `certificate` the float search's
/// certificate counters.
template <typename T, typename Store>
void BoundCudaBvh::search_points(const DeviceBvh<T>& dev, const Vec3d* device_points, int64_t n, double coordinate,
                                 EventTimer& compute, CertificateCounters& certificate, Store store) const {
    reset_certificate(dev);
    // Every device buffer is allocated before the timed work (allocation is not search).
    DeviceBuffer<Vec3d> sorted_points{size_t(n)};
    MortonSort sort(n);
    int64_t step = n;
    if (options_.max_points_per_piece > 0) step = std::min(step, options_.max_points_per_piece);
    // One piece of fewer than 2^31 points: its results gathered into input order by rank;
    // pieces scatter theirs by input position (`order`).
    const bool gather = step == n && n <= int64_t(INT32_MAX);
    DeviceBuffer<int32_t> rank{gather ? size_t(n) : 0};
    DeviceBuffer<int64_t> order{gather ? 0 : size_t(n)};
    const ResultOrder result_order{rank.get()};
    PieceResults r(step);  // reused by every piece
    const int run = list_points_per_thread(step, multiprocessors());
    const bool seeded = list_seeded();
    const StreamedCertify fused = streamed_certify(dev, kernel_, coordinate);
    const WindingSignView sign = dev.winding.view();
    const bool sides = sign.enabled() && sign.certify && sign.surface.front_winding != nullptr &&
                       SamplerSign::winding_options().nearest_sides;
    // The lists where a quarter of the device's free memory holds them (137 bytes a point);
    // otherwise the streamed certificate, which needs none (the same results).
    std::optional<NearListBuffers> lists;
    if (fused.exact != nullptr && kernel_ == BvhGpuKernel::Warp && list_certificate_candidates() &&
        size_t(step) * NearListBuffers::bytes_per_point(near_list_slots()) <= free_device_memory() / 4)
        lists.emplace(step, near_list_slots(), sides);
    const NearLists near_lists = lists ? lists->view() : NearLists{};
    // Every piece's results in r's arrays, in sorted order; the store gathers them by rank
    // or scatters them by output_index.
    PieceOutputs outputs = r.outputs();
    if (result_order.rank != nullptr) outputs.output_index = nullptr;
    NearestSideInputs side_inputs{dev.mesh->view(), sign.surface, sign.view, lists ? lists->side.get() : nullptr};
    side_inputs.out = outputs;
    side_inputs.band_width = options_.band_width;
    if (sign.counts != nullptr) side_inputs.nearest_count = sign.counts + int(WindingStage::Nearest);
    for (int64_t begin = 0; begin < n; begin += step) {
        compute.begin();
        if (begin == 0) sort.run(mesh(), device_points, sorted_points.get(), order.get(), rank.get());
        const SortedPointListPiece piece{sorted_points.get(), order.get(), begin, std::min(step, n - begin)};
        const PointListPiece list{sorted_points.get(), begin, piece.count};
        const auto warp = [&](auto layout) {
            launch_bvh_warp(dev.view, layout, BandSearch{}, fused, r.nearest.get(), near_lists, warp_queue());
        };
        if (kernel_ == BvhGpuKernel::Candidates) {
            const ListLayout layout{list};
            nearest_triangle_bvh_candidates<T><<<blocks_for(layout.threads(), kBvhThreads), kBvhThreads>>>(
                dev.view, layout, BandSearch{}, r.nearest.get(), nullptr);
        } else if (run == 1) {
            warp(ListRuns<1>{list, seeded});
        } else if (run == 2) {
            warp(ListRuns<2>{list, seeded});
        } else {
            warp(ListLayout{list, seeded});
        }
        CUDA_CHECK_LAUNCH("nearest_triangle_bvh (sorted points)");
        if (!fused.exact) certify(dev, piece, coordinate, r.nearest.get());
        if (near_lists.enabled()) rerank_lists(dev, piece, coordinate, near_lists, r.nearest.get(), side_inputs);
        launch_finalize_samples(piece.count, dev.mesh->view(), piece, r.nearest.get(), sign, options_.band_width, outputs,
                                side_inputs.side);
        CUDA_CHECK_LAUNCH("finalize_samples (bvh points)");
        store(r, piece.count, result_order);
        compute.end();
    }
    read_certificate(dev, certificate);
}

}  // namespace sdf::cuda
