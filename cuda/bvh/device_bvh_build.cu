// The GPU build of the linear BVH: one kernel per step of kernels/bvh/lbvh_steps.h, with
// CUB's radix sort and prefix sum between them (docs/bvh.md, "Build on the GPU").
#include "cuda/bvh/device_bvh_build.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include <cub/block/block_scan.cuh>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include "cuda/util/cuda_check.h"
#include "cuda/util/warp_reduce.cuh"
#include "kernels/bvh/lbvh_steps.h"
#include "kernels/distance/packed_triangle.h"

namespace sdf::cuda {
namespace {

constexpr int kThreads = 256;

unsigned blocks_for(int64_t n) { return unsigned((n + kThreads - 1) / kThreads); }

__global__ void lbvh_keys(const Vec3d* vertices, const Int3* triangles, int n, Vec3d lo, double inv_extent,
                          uint64_t* keys, int32_t* identity) {
    const int t = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (t >= n) return;
    keys[t] = lbvh_triangle_key(vertices, triangles, t, lo, inv_extent);
    identity[t] = t;
}

__global__ void lbvh_internal(LbvhArrays a) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < a.n - 1) lbvh_internal_node(a, i);
}

__global__ void lbvh_leaves_in_place(LbvhArrays a) {
    const int pos = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (pos < a.n) lbvh_leaf_in_place(a, pos);
}

__global__ void ploc_init(LbvhArrays a, PlocArrays p) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < a.n) ploc_leaf_cluster(a, p, i);
}

__global__ void ploc_nearest_kernel(PlocArrays p) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < p.m) ploc_nearest(p, i);
}

/// Cluster i's flags (ploc_flags_of) packed for one scan of both: merges in the high 32
/// bits, keeps in the low. Written out, not computed in the scan's input iterator: there
/// its two dependent loads per element made the scan 11-13 us at any size (H200).
__global__ void ploc_flags_kernel(PlocArrays p, int64_t* flags) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= p.m) return;
    int merges = 0, keeps = 0;
    ploc_flags_of(p, i, merges, keeps);
    flags[i] = int64_t(merges) << 32 | keeps;
}

/// Merges and compacts in one pass from p into q (`scan`: the packed flags' exclusive sum);
/// the last thread also writes the iteration's totals (merges, survivors).
__global__ void ploc_merge_compact_kernel(LbvhArrays a, PlocArrays p, PlocArrays q, const int64_t* scan, int next_id,
                                          int32_t* totals) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= p.m) return;
    int merges = 0, keeps = 0;
    ploc_flags_of(p, i, merges, keeps);
    const int merged_before = int(scan[i] >> 32), kept_before = int(scan[i] & 0xffffffff);
    if (keeps) ploc_merge_compact(a, p, q, i, merges != 0, a.n - 2 - (next_id + merged_before), kept_before);
    if (i == p.m - 1) {
        totals[0] = merged_before + merges;
        totals[1] = kept_before + keeps;
    }
}

/// PLOC's last iterations, once at most ploc_tail_capacity() clusters are left: one block
/// runs them all with the clusters in shared memory, the steps of the launches above in the
/// same order (so the same tree), where the launches and a read-back per iteration would
/// cost some 40 us each for little work. Each thread owns the clusters threadIdx.x + k *
/// kPlocTailThreads, k < kPlocTailChunks, and keeps their flags and scans in registers.
constexpr int kPlocTailThreads = 1024;
constexpr int kPlocTailChunks = 6;
constexpr int kPlocTailMaxClusters = kPlocTailThreads * kPlocTailChunks;
/// Shared memory per cluster: its box, code, count and nearest neighbour.
constexpr size_t kPlocTailClusterBytes = 6 * sizeof(float) + 3 * sizeof(int32_t);

/// g: this iteration's clusters in global memory (g.m of them); `status` becomes 1 where an
/// iteration merged nothing (lbvh_steps.h rules it out; checked, not assumed).
__global__ void __launch_bounds__(kPlocTailThreads) ploc_tail_kernel(LbvhArrays a, PlocArrays g, int next_id, int32_t* status) {
    using Scan = cub::BlockScan<int, kPlocTailThreads>;
    __shared__ typename Scan::TempStorage scan_storage;
    extern __shared__ float tail_shared[];
    const int capacity = g.m;
    PlocArrays s = g;
    s.box = tail_shared;
    s.stride = capacity;
    s.code = reinterpret_cast<int32_t*>(tail_shared + 6 * capacity);
    s.count = s.code + capacity;
    s.nearest = s.count + capacity;
    s.merges = s.keeps = nullptr;  // in registers
    const int t = int(threadIdx.x);
    for (int i = t; i < capacity; i += kPlocTailThreads) ploc_store(s, i, ploc_cluster(g, i));
    __syncthreads();
    for (int m = capacity; m > 1;) {
        s.m = m;
        for (int i = t; i < m; i += kPlocTailThreads) ploc_nearest(s, i);
        __syncthreads();
        // Both exclusive sums in one scan: merges in the high 16 bits, keeps (<= m < 2^16) low.
        int flags[kPlocTailChunks], before[kPlocTailChunks];
        int running = 0;
#pragma unroll
        for (int k = 0; k < kPlocTailChunks; ++k) {
            flags[k] = before[k] = 0;
            if (k * kPlocTailThreads >= m) continue;  // the same in every thread
            const int i = k * kPlocTailThreads + t;
            int merges = 0, keeps = 0;
            if (i < m) ploc_flags_of(s, i, merges, keeps);
            flags[k] = merges << 16 | keeps;
            int chunk = 0;
            Scan(scan_storage).ExclusiveSum(flags[k], before[k], chunk);
            before[k] += running;
            running += chunk;
            __syncthreads();  // scan_storage is reused
        }
        const int merges = running >> 16;
        if (merges < 1) {  // the same in every thread: the block leaves together
            if (t == 0) *status = 1;
            return;
        }
        // In place, chunk by chunk: a survivor moves to its place among the survivors
        // (<= its own), after every thread of the chunk has read its cluster (and a merge
        // its neighbour, later in order). Later chunks' clusters lie beyond every place this
        // chunk writes.
#pragma unroll
        for (int k = 0; k < kPlocTailChunks; ++k) {
            if (k * kPlocTailThreads >= m) continue;
            const int i = k * kPlocTailThreads + t;
            const bool survives = (flags[k] & 0xffff) != 0;
            PlocCluster c;
            if (survives)
                c = (flags[k] >> 16) != 0 ? ploc_merged(a, s, i, a.n - 2 - (next_id + (before[k] >> 16))) : ploc_cluster(s, i);
            __syncthreads();
            if (survives) ploc_store(s, before[k] & 0xffff, c);
        }
        __syncthreads();
        next_id += merges;
        m = running & 0xffff;
    }
}

__global__ void ploc_root(LbvhArrays a) { a.parent[0] = -1; }

__global__ void ploc_leaf_slots(LbvhArrays a) {
    const int pos = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (pos < a.n) ploc_leaf_slot(a, pos);
}

__global__ void ploc_first_slots(LbvhArrays a) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < a.n - 1) ploc_first_slot(a, i);
}

__global__ void lbvh_kept_flags(LbvhArrays a, int32_t* flags, uint64_t* preorder, int32_t* identity) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= a.n - 1) return;
    flags[i] = lbvh_kept(a, i) ? 1 : 0;
    preorder[i] = lbvh_preorder_key(a, i);
    identity[i] = i;
}

/// kept_index[node] = its rank in pre-order (the first `kept` of the sorted nodes).
__global__ void lbvh_number_kept(LbvhArrays a, const int32_t* by_key, int kept) {
    const int r = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (r < kept) a.kept_index[by_key[r]] = r;
}

__global__ void lbvh_link(LbvhArrays a) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < a.n - 1 && lbvh_kept(a, i)) lbvh_link_node(a, i);
}

__global__ void lbvh_refit(LbvhArrays a) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < a.n - 1 && lbvh_kept(a, i)) lbvh_refit_from(a, i);
}

/// counters: [0] depth, [1] leaves, [2] largest leaf.
__global__ void lbvh_radius(LbvhArrays a, int* counters) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    int depth = 0, leaves = 0, largest = 0;
    if (i < a.n - 1 && lbvh_kept(a, i)) {
        depth = lbvh_radius_from(a, i);
        for (int c = 0; c < 2; ++c) {
            const int count = lbvh_child_count(a, i, c);
            if (count > a.max_leaf) continue;
            ++leaves;
            largest = max(largest, count);
        }
    }
    // One atomic per warp and counter: the node's own would serialise on three addresses.
    depth = warp_max(depth);
    leaves = warp_sum(leaves);
    largest = warp_max(largest);
    if (threadIdx.x % 32 == 0 && leaves > 0) {
        atomicMax(&counters[0], depth);
        atomicAdd(&counters[1], leaves);
        atomicMax(&counters[2], largest);
    }
}

/// The SAH cost figure (BvhBuildStats::sah_cost, as bvh_sah_cost() sums it on the host;
/// here in another order, so equal to rounding).
__global__ void lbvh_sah(const BvhNode* nodes, int num_nodes, double node_cost, double* sum) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    auto area = [](const BvhNode& n, int c) {
        const double ex = double(n.max_x[c]) - n.min_x[c], ey = double(n.max_y[c]) - n.min_y[c],
                     ez = double(n.max_z[c]) - n.min_z[c];
        return ex < 0 ? 0.0 : 2.0 * (ex * ey + ey * ez + ez * ex);
    };
    double cost = 0.0;
    if (i < num_nodes) {
        const BvhNode& root = nodes[0];
        double lo[3] = {fmin(root.min_x[0], root.min_x[1]), fmin(root.min_y[0], root.min_y[1]), fmin(root.min_z[0], root.min_z[1])};
        double hi[3] = {fmax(root.max_x[0], root.max_x[1]), fmax(root.max_y[0], root.max_y[1]), fmax(root.max_z[0], root.max_z[1])};
        const double ex = hi[0] - lo[0], ey = hi[1] - lo[1], ez = hi[2] - lo[2];
        const double root_area = fmax(2.0 * (ex * ey + ey * ez + ez * ex), 1e-300);
        const BvhNode& n = nodes[i];
        cost = i == 0 ? node_cost : 0.0;
        for (int c = 0; c < 2; ++c)
            cost += area(n, c) / root_area * (n.count[c] > 0 ? double(n.count[c]) : (n.ref[c] > 0 ? node_cost : 0.0));
    }
    cost = warp_sum(cost);  // one atomic per warp
    if (threadIdx.x % 32 == 0 && cost != 0.0) atomicAdd(sum, cost);
}

/// The packed constants of the triangle in slot s, made here (pack_triangle() computes them
/// bit for bit as the host's mesh buffers hold them): cheaper than uploading the host's.
/// `out_f` and `slot_of` may be null (a double search without the float certificate).
__global__ void lbvh_pack(const Vec3d* vertices, const Int3* triangles, const int32_t* order, int n,
                          PackedTriangle<float>* out_f, PackedTriangle<double>* out_d, int32_t* slot_of) {
    const int s = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (s >= n) return;
    const int32_t t = order[s];
    const Int3 tri = triangles[t];
    const Vec3d v0 = vertices[tri.x], v1 = vertices[tri.y], v2 = vertices[tri.z];
    if (out_f) out_f[s] = pack_triangle<float>(v0, v1, v2);
    out_d[s] = pack_triangle<double>(v0, v1, v2);
    if (slot_of) slot_of[t] = s;
}

void check_launch(const char* what) {
    const cudaError_t e = cudaGetLastError();
    if (e != cudaSuccess) throw std::runtime_error(std::string("CUDA BVH build: ") + what + ": " + cudaGetErrorString(e));
}

}  // namespace

/// The clusters ploc_tail_kernel can hold on the current device (its shared memory per
/// block): kPlocTailMaxClusters on an H200, about 1,700 on sm_75.
static int ploc_tail_capacity() {
    int device = 0, optin = 0;
    CUDA_CHECK(cudaGetDevice(&device));
    CUDA_CHECK(cudaDeviceGetAttribute(&optin, cudaDevAttrMaxSharedMemoryPerBlockOptin, device));
    cudaFuncAttributes attributes{};
    CUDA_CHECK(cudaFuncGetAttributes(&attributes, ploc_tail_kernel));
    const int64_t room = int64_t(optin) - int64_t(attributes.sharedSizeBytes);
    return int(std::max<int64_t>(0, std::min<int64_t>(kPlocTailMaxClusters, room / int64_t(kPlocTailClusterBytes))));
}

/// PLOC's iterations (lbvh_steps.h): per iteration the nearest neighbours, their flags, one
/// CUB scan of both and one merge-and-compact pass, the iteration's totals read back to know how
/// many clusters are left; the last iterations in one block (ploc_tail_kernel), from at most
/// `tail_clusters` (or what the device's shared memory holds).
static void ploc_on_device(const LbvhArrays& a, int radius, int tail_clusters, DeviceBuffer<unsigned char>& temp) {
    const size_t n = size_t(a.n);
    DeviceBuffer<int32_t> code[2] = {DeviceBuffer<int32_t>(n), DeviceBuffer<int32_t>(n)};
    DeviceBuffer<int32_t> count[2] = {DeviceBuffer<int32_t>(n), DeviceBuffer<int32_t>(n)};
    DeviceBuffer<float> box[2] = {DeviceBuffer<float>(6 * n), DeviceBuffer<float>(6 * n)};
    DeviceBuffer<int32_t> nearest(n), totals(2);
    DeviceBuffer<int64_t> flags(n), scan(n);
    auto arrays = [&](int k, int clusters) {
        return PlocArrays{clusters, radius, code[k].get(), box[k].get(), count[k].get(), nearest.get(), nullptr, nullptr, a.n};
    };
    size_t scan_bytes = 0;
    CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, scan_bytes, flags.get(), scan.get(), a.n));
    if (scan_bytes > temp.size()) temp.allocate(scan_bytes);
    const int capacity = ploc_tail_capacity();
    const int tail = std::min(tail_clusters, capacity);
    int cur = 0, m = a.n, next_id = 0;
    ploc_init<<<blocks_for(a.n), kThreads>>>(a, arrays(0, m));
    check_launch("ploc init");
    while (m > 1 && m > tail) {
        const PlocArrays p = arrays(cur, m), q = arrays(1 - cur, 0);
        ploc_nearest_kernel<<<blocks_for(m), kThreads>>>(p);
        ploc_flags_kernel<<<blocks_for(m), kThreads>>>(p, flags.get());
        check_launch("ploc nearest");
        size_t bytes = temp.size();
        CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp.get(), bytes, flags.get(), scan.get(), m));
        ploc_merge_compact_kernel<<<blocks_for(m), kThreads>>>(a, p, q, scan.get(), next_id, totals.get());
        check_launch("ploc merge");
        int32_t t[2] = {0, 0};
        CUDA_CHECK(cudaMemcpy(t, totals.get(), sizeof(t), cudaMemcpyDeviceToHost));
        if (t[0] < 1) throw std::logic_error("CUDA BVH build: a PLOC iteration merged nothing");
        next_id += t[0];
        m = t[1];
        cur = 1 - cur;
    }
    if (m > 1) {
        const size_t shared = size_t(m) * kPlocTailClusterBytes;
        // The kernel's limit is the device's whole capacity, the same for every build: a
        // limit of this build's size could be lowered by another thread's build before
        // this launch.
        CUDA_CHECK(cudaFuncSetAttribute(ploc_tail_kernel, cudaFuncAttributeMaxDynamicSharedMemorySize,
                                        int(size_t(capacity) * kPlocTailClusterBytes)));
        CUDA_CHECK(cudaMemsetAsync(totals.get(), 0, sizeof(int32_t)));
        ploc_tail_kernel<<<1, kPlocTailThreads, shared>>>(a, arrays(cur, m), next_id, totals.get());
        check_launch("ploc tail");
        int32_t status = 0;
        CUDA_CHECK(cudaMemcpy(&status, totals.get(), sizeof(status), cudaMemcpyDeviceToHost));
        if (status != 0) throw std::logic_error("CUDA BVH build: a PLOC iteration merged nothing");
    }
    ploc_root<<<1, 1>>>(a);
    ploc_leaf_slots<<<blocks_for(a.n), kThreads>>>(a);
    check_launch("ploc slots");
    ploc_first_slots<<<blocks_for(a.n - 1), kThreads>>>(a);
    check_launch("ploc first slots");
}

template <>
BvhView<float> DeviceLbvh::view<float>() const {
    return {nodes.get(), packed_float.get(), triangle_index.get(), num_nodes, num_triangles};
}

template <>
BvhView<double> DeviceLbvh::view<double>() const {
    BvhView<double> v{nodes.get(), packed_double.get(), triangle_index.get(), num_nodes, num_triangles};
    v.margin = double_prune_margin(bound);  // as TriangleBvh::view<double>(): the double search is the brute force's
    return v;
}

LbvhBuild DeviceLbvh::download() const {
    LbvhBuild b;
    b.bvh.nodes.resize(size_t(num_nodes));
    b.moments.resize(size_t(num_nodes));
    b.bvh.triangle_index.resize(size_t(num_triangles));
    b.bvh.packed_float.resize(size_t(num_triangles));
    b.bvh.packed_double.resize(size_t(num_triangles));
    nodes.download(b.bvh.nodes.data(), size_t(num_nodes));
    moments.download(b.moments.data(), size_t(num_nodes));
    triangle_index.download(b.bvh.triangle_index.data(), size_t(num_triangles));
    packed_float.download(b.bvh.packed_float.data(), size_t(num_triangles));
    packed_double.download(b.bvh.packed_double.data(), size_t(num_triangles));
    CUDA_CHECK(cudaStreamSynchronize(0));
    b.bvh.stats = stats;
    b.bvh.float_bound = bound;
    b.within_depth = within_depth;
    return b;
}

std::unique_ptr<DeviceLbvh> build_lbvh_on_device(const PreparedMesh& mesh, const Vec3d* vertices, const Int3* triangles,
                                                 const GpuBvhBuildOptions& options) {
    const int n = int(mesh.triangles().size());
    if (options.max_leaf < 1 || options.ploc_radius < 1)
        throw std::invalid_argument("CUDA BVH build: max_leaf and ploc_radius must be >= 1");
    if (options.ploc_tail_clusters < 0)
        throw std::invalid_argument("CUDA BVH build: ploc_tail_clusters must be >= 0, got " +
                                    std::to_string(options.ploc_tail_clusters));
    if (n <= options.max_leaf) return nullptr;
    const auto start = std::chrono::steady_clock::now();
    EventTimer timer;
    timer.begin();
    auto out = std::make_unique<DeviceLbvh>();
    DeviceLbvh& d = *out;
    d.num_triangles = n;

    const LbvhKeyFrame frame = lbvh_key_frame(mesh.bounds());
    const size_t count = mesh.triangles().size();
    DeviceBuffer<uint64_t> keys_in(count), keys(count);
    DeviceBuffer<int32_t> identity(count), identity_sorted(count);
    d.triangle_index.allocate(count);
    lbvh_keys<<<blocks_for(n), kThreads>>>(vertices, triangles, n, frame.lo, frame.inv_extent, keys_in.get(), identity.get());
    check_launch("keys");
    size_t temp_bytes = 0;
    CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, keys_in.get(), keys.get(), identity.get(),
                                               identity_sorted.get(), n, 0, 63));
    DeviceBuffer<unsigned char> temp(temp_bytes);
    CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp.get(), temp_bytes, keys_in.get(), keys.get(), identity.get(),
                                               identity_sorted.get(), n, 0, 63));

    const size_t internal = size_t(n - 1);
    DeviceBuffer<int32_t> left(internal), right(internal), parent(internal), leaf_parent(count), node_count(internal),
        first(internal), leaf_slot(count), kept_index(internal), flags(internal), by_key(internal);
    DeviceBuffer<uint32_t> arrivals(internal);
    CUDA_CHECK(cudaMemsetAsync(arrivals.get(), 0, internal * sizeof(uint32_t)));
    LbvhArrays a;
    a.n = n;
    a.max_leaf = options.max_leaf;
    a.vertices = vertices;
    a.triangles = triangles;
    a.keys = keys.get();
    a.sorted = identity_sorted.get();
    a.left = left.get();
    a.right = right.get();
    a.parent = parent.get();
    a.leaf_parent = leaf_parent.get();
    a.count = node_count.get();
    a.first = first.get();
    a.leaf_slot = leaf_slot.get();
    a.order = d.triangle_index.get();
    a.kept_index = kept_index.get();
    a.arrivals = arrivals.get();
    if (options.builder == GpuBvhBuilder::Lbvh) {
        lbvh_internal<<<blocks_for(n - 1), kThreads>>>(a);
        check_launch("radix tree");
        lbvh_leaves_in_place<<<blocks_for(n), kThreads>>>(a);
        check_launch("leaves");
    } else {
        ploc_on_device(a, options.ploc_radius, options.ploc_tail_clusters, temp);
    }

    // Kept nodes, numbered in pre-order (lbvh_preorder_key).
    DeviceBuffer<uint64_t> preorder(internal), preorder_sorted(internal);
    DeviceBuffer<int32_t> node_ids(internal);
    lbvh_kept_flags<<<blocks_for(n - 1), kThreads>>>(a, flags.get(), preorder.get(), node_ids.get());
    check_launch("kept flags");
    size_t scan_bytes = 0;
    CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, scan_bytes, flags.get(), kept_index.get(), int(internal)));
    if (scan_bytes > temp.size()) temp.allocate(scan_bytes);
    CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp.get(), scan_bytes, flags.get(), kept_index.get(), int(internal)));
    int32_t tail[2] = {0, 0};
    CUDA_CHECK(cudaMemcpy(&tail[0], kept_index.get() + internal - 1, sizeof(int32_t), cudaMemcpyDeviceToHost));
    CUDA_CHECK(cudaMemcpy(&tail[1], flags.get() + internal - 1, sizeof(int32_t), cudaMemcpyDeviceToHost));
    d.num_nodes = tail[0] + tail[1];
    if (d.num_nodes < 1 || int64_t(d.num_nodes) > int64_t(internal))  // read back from the device: checked before it sizes anything
        throw std::runtime_error("GPU BVH build of mesh '" + mesh.name() + "': " + std::to_string(d.num_nodes) +
                                 " nodes kept, expected 1.." + std::to_string(internal));
    size_t sort_bytes = 0;
    CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, sort_bytes, preorder.get(), preorder_sorted.get(), node_ids.get(),
                                               by_key.get(), int(internal)));
    if (sort_bytes > temp.size()) temp.allocate(sort_bytes);
    CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp.get(), sort_bytes, preorder.get(), preorder_sorted.get(), node_ids.get(),
                                               by_key.get(), int(internal)));
    lbvh_number_kept<<<blocks_for(d.num_nodes), kThreads>>>(a, by_key.get(), d.num_nodes);
    check_launch("pre-order");

    d.nodes.allocate(size_t(d.num_nodes));
    d.moments.allocate(size_t(d.num_nodes));
    DeviceBuffer<Vec3d> weighted(2 * size_t(d.num_nodes));
    a.nodes = d.nodes.get();
    a.moments = d.moments.get();
    a.weighted = weighted.get();
    lbvh_link<<<blocks_for(n - 1), kThreads>>>(a);
    check_launch("link");
    lbvh_refit<<<blocks_for(n - 1), kThreads>>>(a);
    check_launch("refit");
    DeviceBuffer<int> counters(3);
    CUDA_CHECK(cudaMemsetAsync(counters.get(), 0, 3 * sizeof(int)));
    lbvh_radius<<<blocks_for(n - 1), kThreads>>>(a, counters.get());
    check_launch("radius");
    DeviceBuffer<double> sah(1);
    CUDA_CHECK(cudaMemsetAsync(sah.get(), 0, sizeof(double)));
    lbvh_sah<<<blocks_for(d.num_nodes), kThreads>>>(d.nodes.get(), d.num_nodes, 1.0, sah.get());
    check_launch("sah");

    d.packed_float.allocate(count);
    d.packed_double.allocate(count);
    d.slot_of.allocate(count);
    lbvh_pack<<<blocks_for(n), kThreads>>>(vertices, triangles, d.triangle_index.get(), n, d.packed_float.get(),
                                           d.packed_double.get(), d.slot_of.get());
    check_launch("pack");
    int h[3] = {0, 0, 0};
    double sah_cost = 0;
    counters.download(h, 3);
    sah.download(&sah_cost, 1);
    timer.end();  // synchronises
    d.device_seconds = timer.seconds();
    d.stats.nodes = d.num_nodes;
    d.stats.depth = h[0];
    d.stats.leaves = h[1];
    d.stats.largest_leaf = h[2];
    d.stats.sah_cost = sah_cost;
    d.within_depth = h[0] <= kBvhMaxDepth;
    d.bound = mesh.search_bound();  // made with the mesh (a host pass of 1-3 ms at 100k triangles)
    d.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

void pack_in_slot_order(const Vec3d* vertices, const Int3* triangles, const int32_t* order, int n,
                        PackedTriangle<float>* packed_float, PackedTriangle<double>* packed_double, int32_t* slot_of) {
    if (n <= 0) return;
    lbvh_pack<<<blocks_for(n), kThreads>>>(vertices, triangles, order, n, packed_float, packed_double, slot_of);
    check_launch("pack");
}

}  // namespace sdf::cuda
