#include "core/bvh/lbvh.h"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <stdexcept>
#include <string>

#include "kernels/bvh/lbvh_steps.h"

namespace sdf {

LbvhKeyFrame lbvh_key_frame(const Bounds3& box) {
    const Vec3d e = box.extent();
    const double extent = std::max({e.x, e.y, e.z});
    return {box.min, extent > 0 ? 1.0 / extent : 1.0};
}

LbvhBuild build_lbvh(const BvhBuildInput& mesh, const Bounds3& box, int max_leaf) {
    const int n = int(mesh.triangles.size());
    if (max_leaf < 1 || n <= max_leaf)
        throw std::invalid_argument("LBVH build: mesh '" + mesh.name + "' needs more than max_leaf = " +
                                    std::to_string(max_leaf) + " triangles, has " + std::to_string(n));
    if (mesh.packed_float.size() != size_t(n) || mesh.packed_double.size() != size_t(n))
        throw std::invalid_argument("LBVH build: mesh '" + mesh.name + "': one packed triangle per triangle expected");
    const auto start = std::chrono::steady_clock::now();
    const LbvhKeyFrame frame = lbvh_key_frame(box);

    // Keys, sorted with their triangles (ties in triangle order, as a stable radix sort leaves them).
    const size_t count = mesh.triangles.size();
    std::vector<uint64_t> unsorted(count), keys(count);
    for (int t = 0; t < n; ++t)
        unsorted[size_t(t)] = lbvh_triangle_key(mesh.vertices.data(), mesh.triangles.data(), t, frame.lo, frame.inv_extent);
    std::vector<int32_t> order(count);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int32_t a, int32_t b) { return unsorted[size_t(a)] < unsorted[size_t(b)]; });
    for (int s = 0; s < n; ++s) keys[size_t(s)] = unsorted[size_t(order[size_t(s)])];

    const size_t internal = size_t(n - 1);
    std::vector<int32_t> first(internal), last(internal), split(internal), parent(internal), kept_index(internal);
    std::vector<uint32_t> arrivals(internal, 0);
    LbvhArrays a;
    a.n = n;
    a.max_leaf = max_leaf;
    a.vertices = mesh.vertices.data();
    a.triangles = mesh.triangles.data();
    a.keys = keys.data();
    a.order = order.data();
    a.first = first.data();
    a.last = last.data();
    a.split = split.data();
    a.parent = parent.data();
    a.kept_index = kept_index.data();
    a.arrivals = arrivals.data();
    for (int i = 0; i < n - 1; ++i) lbvh_internal_node(a, i);

    int kept = 0;  // the exclusive prefix sum of the kept flags
    for (int i = 0; i < n - 1; ++i) {
        kept_index[size_t(i)] = kept;
        kept += lbvh_kept(a, i) ? 1 : 0;
    }
    LbvhBuild out;
    TriangleBvh& bvh = out.bvh;
    bvh.nodes.assign(size_t(kept), BvhNode{});
    out.moments.assign(size_t(kept), WindingNode<double>{});
    std::vector<Vec3d> weighted(2 * size_t(kept), Vec3d(0.0));
    a.nodes = bvh.nodes.data();
    a.moments = out.moments.data();
    a.weighted = weighted.data();
    for (int i = 0; i < n - 1; ++i)
        if (lbvh_kept(a, i)) lbvh_link_node(a, i);
    for (int i = 0; i < n - 1; ++i)
        if (lbvh_kept(a, i)) lbvh_refit_from(a, i);
    int depth = 0;
    for (int i = 0; i < n - 1; ++i)
        if (lbvh_kept(a, i)) depth = std::max(depth, lbvh_radius_from(a, i));

    bvh.triangle_index = order;
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
    return out;
}

}  // namespace sdf
