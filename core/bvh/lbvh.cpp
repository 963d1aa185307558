#include "core/bvh/lbvh.h"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

#include "core/bvh/search_bound.h"
#include "kernels/bvh/lbvh_steps.h"

namespace sdf {

LbvhKeyFrame lbvh_key_frame(const Bounds3& box) {
    const Vec3d e = box.extent();
    const double extent = std::max({e.x, e.y, e.z});
    return {box.min, extent > 0 ? 1.0 / extent : 1.0};
}

const char* gpu_bvh_builder_name(GpuBvhBuilder b) { return b == GpuBvhBuilder::Lbvh ? "lbvh" : "ploc"; }

namespace {

/// Runs f(i) for i in [0, count): in order, or (seed != 0) in a shuffled order, as a GPU
/// launch may run its threads; every step must give the same result either way.
class Elements {
public:
    explicit Elements(uint64_t seed) : rng_(seed), shuffle_(seed != 0) {}

    template <class F>
    void each(int count, F&& f) {
        order_.resize(size_t(count));
        std::iota(order_.begin(), order_.end(), 0);
        if (shuffle_) std::shuffle(order_.begin(), order_.end(), rng_);
        for (int i : order_) f(i);
    }

private:
    std::mt19937_64 rng_;
    bool shuffle_;
    std::vector<int> order_;
};

/// Exclusive prefix sum of flags[0, m) into scan; returns the total.
int exclusive_sum(const int32_t* flags, int32_t* scan, int m) {
    int total = 0;
    for (int i = 0; i < m; ++i) {
        scan[i] = total;
        total += flags[i];
    }
    return total;
}

/// PLOC, step by step as the device runs it (cuda/bvh/device_bvh_build.cu).
void ploc_tree(const LbvhArrays& a, int radius, Elements& elements) {
    const size_t n = size_t(a.n);
    std::vector<int32_t> code(n), count(n), nearest(n), merges(n), keeps(n), code2(n), count2(n), merge_scan(n), keep_scan(n);
    std::vector<float> box(6 * n), box2(6 * n);
    PlocArrays p{a.n, radius, code.data(), box.data(), count.data(), nearest.data(), merges.data(), keeps.data(), a.n};
    PlocArrays q{0, radius, code2.data(), box2.data(), count2.data(), nearest.data(), merges.data(), keeps.data(), a.n};
    elements.each(a.n, [&](int i) { ploc_leaf_cluster(a, p, i); });
    int next_id = 0;  // merges so far; node id = n - 2 - merge number
    while (p.m > 1) {
        elements.each(p.m, [&](int i) { ploc_nearest(p, i); });
        elements.each(p.m, [&](int i) { ploc_flags(p, i); });
        const int merged = exclusive_sum(p.merges, merge_scan.data(), p.m);
        const int kept = exclusive_sum(p.keeps, keep_scan.data(), p.m);
        if (merged < 1) throw std::logic_error("GPU BVH build: a PLOC iteration merged nothing");
        elements.each(p.m, [&](int i) {
            if (p.keeps[i])
                ploc_merge_compact(a, p, q, i, p.merges[i] != 0, a.n - 2 - (next_id + merge_scan[size_t(i)]), keep_scan[size_t(i)]);
        });
        next_id += merged;
        std::swap(p.code, q.code);
        std::swap(p.box, q.box);
        std::swap(p.count, q.count);
        p.m = kept;
    }
    a.parent[0] = -1;
    elements.each(a.n, [&](int pos) { ploc_leaf_slot(a, pos); });
    elements.each(a.n - 1, [&](int i) { ploc_first_slot(a, i); });
}

}  // namespace

LbvhBuild build_lbvh(const BvhBuildInput& mesh, const Bounds3& box, const GpuBvhBuildOptions& options) {
    const int max_leaf = options.max_leaf;
    const int n = int(mesh.triangles.size());
    if (max_leaf < 1 || n <= max_leaf)
        throw std::invalid_argument("GPU BVH build: mesh '" + mesh.name + "' needs more than max_leaf = " +
                                    std::to_string(max_leaf) + " triangles, has " + std::to_string(n));
    if (options.ploc_radius < 1)
        throw std::invalid_argument("GPU BVH build: ploc_radius must be >= 1, got " + std::to_string(options.ploc_radius));
    if (mesh.packed_float.size() != size_t(n) || mesh.packed_double.size() != size_t(n))
        throw std::invalid_argument("GPU BVH build: mesh '" + mesh.name + "': one packed triangle per triangle expected");
    const auto start = std::chrono::steady_clock::now();
    const LbvhKeyFrame frame = lbvh_key_frame(box);

    // Keys, sorted with their triangles (ties in triangle order, as a stable radix sort leaves them).
    const size_t count = mesh.triangles.size();
    std::vector<uint64_t> unsorted(count), keys(count);
    for (int t = 0; t < n; ++t)
        unsorted[size_t(t)] = lbvh_triangle_key(mesh.vertices.data(), mesh.triangles.data(), t, frame.lo, frame.inv_extent);
    std::vector<int32_t> sorted(count);
    std::iota(sorted.begin(), sorted.end(), 0);
    std::stable_sort(sorted.begin(), sorted.end(), [&](int32_t a, int32_t b) { return unsorted[size_t(a)] < unsorted[size_t(b)]; });
    for (int s = 0; s < n; ++s) keys[size_t(s)] = unsorted[size_t(sorted[size_t(s)])];

    const size_t internal = size_t(n - 1);
    std::vector<int32_t> left(internal), right(internal), parent(internal), leaf_parent(count), node_count(internal),
        first(internal), leaf_slot(count), order(count), kept_index(internal);
    std::vector<uint32_t> arrivals(internal, 0);
    LbvhArrays a;
    a.n = n;
    a.max_leaf = max_leaf;
    a.vertices = mesh.vertices.data();
    a.triangles = mesh.triangles.data();
    a.keys = keys.data();
    a.sorted = sorted.data();
    a.left = left.data();
    a.right = right.data();
    a.parent = parent.data();
    a.leaf_parent = leaf_parent.data();
    a.count = node_count.data();
    a.first = first.data();
    a.leaf_slot = leaf_slot.data();
    a.order = order.data();
    a.kept_index = kept_index.data();
    a.arrivals = arrivals.data();
    Elements elements(options.emulation_shuffle_seed);
    if (options.builder == GpuBvhBuilder::Lbvh) {
        elements.each(n - 1, [&](int i) { lbvh_internal_node(a, i); });
        elements.each(n, [&](int pos) { lbvh_leaf_in_place(a, pos); });
    } else {
        ploc_tree(a, options.ploc_radius, elements);
    }

    // Kept nodes numbered in pre-order: their rank by lbvh_preorder_key (the root's is 0).
    std::vector<uint64_t> preorder(internal);
    std::vector<int32_t> by_key(internal);
    for (int i = 0; i < n - 1; ++i) preorder[size_t(i)] = lbvh_preorder_key(a, i);
    std::iota(by_key.begin(), by_key.end(), 0);
    std::stable_sort(by_key.begin(), by_key.end(), [&](int32_t x, int32_t y) { return preorder[size_t(x)] < preorder[size_t(y)]; });
    int kept = 0;
    for (int i = 0; i < n - 1; ++i) kept += lbvh_kept(a, i) ? 1 : 0;
    for (int r = 0; r < kept; ++r) kept_index[size_t(by_key[size_t(r)])] = r;
    LbvhBuild out;
    TriangleBvh& bvh = out.bvh;
    bvh.nodes.assign(size_t(kept), BvhNode{});
    out.moments.assign(size_t(kept), WindingNode<double>{});
    std::vector<Vec3d> weighted(2 * size_t(kept), Vec3d(0.0));
    a.nodes = bvh.nodes.data();
    a.moments = out.moments.data();
    a.weighted = weighted.data();
    elements.each(n - 1, [&](int i) {
        if (lbvh_kept(a, i)) lbvh_link_node(a, i);
    });
    elements.each(n - 1, [&](int i) {
        if (lbvh_kept(a, i)) lbvh_refit_from(a, i);
    });
    int depth = 0;
    elements.each(n - 1, [&](int i) {
        if (lbvh_kept(a, i)) depth = std::max(depth, lbvh_radius_from(a, i));
    });

    bvh.triangle_index.assign(order.begin(), order.end());
    bvh.packed_float.resize(count);
    bvh.packed_double.resize(count);
    for (int s = 0; s < n; ++s) {
        bvh.packed_float[size_t(s)] = mesh.packed_float[size_t(order[size_t(s)])];
        bvh.packed_double[size_t(s)] = mesh.packed_double[size_t(order[size_t(s)])];
    }
    BvhBuildStats& st = bvh.stats;
    st.nodes = kept;
    st.depth = depth;
    for (const BvhNode& node : bvh.nodes)
        for (int c = 0; c < 2; ++c)
            if (node.count[c] > 0) { ++st.leaves; st.largest_leaf = std::max(st.largest_leaf, int(node.count[c])); }
    st.sah_cost = bvh_sah_cost(bvh.nodes);
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    out.within_depth = depth <= kBvhMaxDepth;
    // The search bound, as build_triangle_bvh() keeps it (the double view's pruning margin).
    bvh.float_bound = mesh.search_bound ? *mesh.search_bound
                                       : float_search_bound(mesh.vertices, mesh.triangles, mesh.packed_double, mesh.packed_float);
    return out;
}

}  // namespace sdf
