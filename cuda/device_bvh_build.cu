// The GPU build of the linear BVH: one kernel per step of kernels/bvh/lbvh_steps.h, with
// CUB's radix sort and prefix sum between them (docs/bvh.md, "Build on the GPU").
#include "cuda/device_bvh_build.h"

#include <chrono>
#include <stdexcept>

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include "cuda/cuda_check.h"
#include "kernels/bvh/lbvh_steps.h"

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

__global__ void lbvh_kept_flags(LbvhArrays a, int32_t* flags) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < a.n - 1) flags[i] = lbvh_kept(a, i) ? 1 : 0;
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
    if (i >= a.n - 1 || !lbvh_kept(a, i)) return;
    atomicMax(&counters[0], lbvh_radius_from(a, i));
    for (int c = 0; c < 2; ++c) {
        const int count = lbvh_child_count(a, i, c);
        if (count > a.max_leaf) continue;
        atomicAdd(&counters[1], 1);
        atomicMax(&counters[2], count);
    }
}

/// The SAH cost figure (BvhBuildStats::sah_cost, as bvh_sah_cost() sums it on the host;
/// here in another order, so equal to rounding).
__global__ void lbvh_sah(const BvhNode* nodes, int num_nodes, double node_cost, double* sum) {
    const int i = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= num_nodes) return;
    auto area = [](const BvhNode& n, int c) {
        const double ex = double(n.max_x[c]) - n.min_x[c], ey = double(n.max_y[c]) - n.min_y[c],
                     ez = double(n.max_z[c]) - n.min_z[c];
        return ex < 0 ? 0.0 : 2.0 * (ex * ey + ey * ez + ez * ex);
    };
    const BvhNode& root = nodes[0];
    double lo[3] = {fmin(root.min_x[0], root.min_x[1]), fmin(root.min_y[0], root.min_y[1]), fmin(root.min_z[0], root.min_z[1])};
    double hi[3] = {fmax(root.max_x[0], root.max_x[1]), fmax(root.max_y[0], root.max_y[1]), fmax(root.max_z[0], root.max_z[1])};
    const double ex = hi[0] - lo[0], ey = hi[1] - lo[1], ez = hi[2] - lo[2];
    const double root_area = fmax(2.0 * (ex * ey + ey * ez + ez * ex), 1e-300);
    const BvhNode& n = nodes[i];
    double cost = i == 0 ? node_cost : 0.0;
    for (int c = 0; c < 2; ++c)
        cost += area(n, c) / root_area * (n.count[c] > 0 ? double(n.count[c]) : (n.ref[c] > 0 ? node_cost : 0.0));
    atomicAdd(sum, cost);
}

__global__ void lbvh_gather(const int32_t* order, int n, const PackedTriangle<float>* pf, const PackedTriangle<double>* pd,
                            PackedTriangle<float>* out_f, PackedTriangle<double>* out_d, int32_t* slot_of) {
    const int s = int(blockIdx.x) * blockDim.x + threadIdx.x;
    if (s >= n) return;
    const int32_t t = order[s];
    out_f[s] = pf[t];
    out_d[s] = pd[t];
    slot_of[t] = s;
}

void check_launch(const char* what) {
    const cudaError_t e = cudaGetLastError();
    if (e != cudaSuccess) throw std::runtime_error(std::string("CUDA BVH build: ") + what + ": " + cudaGetErrorString(e));
}

}  // namespace

template <>
BvhView<float> DeviceLbvh::view<float>() const {
    return {nodes.get(), packed_float.get(), triangle_index.get(), num_nodes, num_triangles};
}

template <>
BvhView<double> DeviceLbvh::view<double>() const {
    return {nodes.get(), packed_double.get(), triangle_index.get(), num_nodes, num_triangles};
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
    b.within_depth = within_depth;
    return b;
}

std::unique_ptr<DeviceLbvh> build_lbvh_on_device(const PreparedMesh& mesh, const Vec3d* vertices, const Int3* triangles,
                                                 int max_leaf) {
    const int n = int(mesh.triangles().size());
    if (max_leaf < 1) throw std::invalid_argument("CUDA BVH build: max_leaf must be >= 1");
    if (n <= max_leaf) return nullptr;
    const auto start = std::chrono::steady_clock::now();
    EventTimer timer;
    timer.begin();
    auto out = std::make_unique<DeviceLbvh>();
    DeviceLbvh& d = *out;
    d.num_triangles = n;

    // The packed constants in triangle order go up while the tree is built.
    DeviceBuffer<PackedTriangle<float>> pf;
    DeviceBuffer<PackedTriangle<double>> pd;
    pf.upload(mesh.buffers<float>().packed);
    pd.upload(mesh.buffers<double>().packed);

    const LbvhKeyFrame frame = lbvh_key_frame(mesh.bounds());
    const size_t count = mesh.triangles().size();
    DeviceBuffer<uint64_t> keys_in(count), keys(count);
    DeviceBuffer<int32_t> identity(count);
    d.triangle_index.allocate(count);
    lbvh_keys<<<blocks_for(n), kThreads>>>(vertices, triangles, n, frame.lo, frame.inv_extent, keys_in.get(), identity.get());
    check_launch("keys");
    size_t temp_bytes = 0;
    CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, keys_in.get(), keys.get(), identity.get(),
                                               d.triangle_index.get(), n, 0, 63));
    DeviceBuffer<unsigned char> temp(temp_bytes);
    CUDA_CHECK(cub::DeviceRadixSort::SortPairs(temp.get(), temp_bytes, keys_in.get(), keys.get(), identity.get(),
                                               d.triangle_index.get(), n, 0, 63));

    const size_t internal = size_t(n - 1);
    DeviceBuffer<int32_t> first(internal), last(internal), split(internal), parent(internal), kept_index(internal), flags(internal);
    DeviceBuffer<uint32_t> arrivals(internal);
    CUDA_CHECK(cudaMemsetAsync(arrivals.get(), 0, internal * sizeof(uint32_t)));
    LbvhArrays a;
    a.n = n;
    a.max_leaf = max_leaf;
    a.vertices = vertices;
    a.triangles = triangles;
    a.keys = keys.get();
    a.order = d.triangle_index.get();
    a.first = first.get();
    a.last = last.get();
    a.split = split.get();
    a.parent = parent.get();
    a.kept_index = kept_index.get();
    a.arrivals = arrivals.get();
    lbvh_internal<<<blocks_for(n - 1), kThreads>>>(a);
    check_launch("radix tree");
    lbvh_kept_flags<<<blocks_for(n - 1), kThreads>>>(a, flags.get());
    check_launch("kept flags");
    size_t scan_bytes = 0;
    CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, scan_bytes, flags.get(), kept_index.get(), int(internal)));
    if (scan_bytes > temp.size()) temp.allocate(scan_bytes);
    CUDA_CHECK(cub::DeviceScan::ExclusiveSum(temp.get(), scan_bytes, flags.get(), kept_index.get(), int(internal)));
    int32_t tail[2] = {0, 0};
    CUDA_CHECK(cudaMemcpy(&tail[0], kept_index.get() + internal - 1, sizeof(int32_t), cudaMemcpyDeviceToHost));
    CUDA_CHECK(cudaMemcpy(&tail[1], flags.get() + internal - 1, sizeof(int32_t), cudaMemcpyDeviceToHost));
    d.num_nodes = tail[0] + tail[1];

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
    lbvh_gather<<<blocks_for(n), kThreads>>>(d.triangle_index.get(), n, pf.get(), pd.get(), d.packed_float.get(),
                                             d.packed_double.get(), d.slot_of.get());
    check_launch("gather");
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
    d.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

}  // namespace sdf::cuda
