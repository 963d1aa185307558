#include "core/bvh/triangle_bvh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/bvh/search_bound.h"
#include "kernels/core/directed_rounding.h"

namespace sdf {
namespace {

/// One triangle as the builder sorts it.
struct BuildRef {
    Bounds3 box;
    Vec3d centroid;
    int32_t triangle;
    uint8_t bin[3];  ///< its SAH bin on each axis at the node being split (in the padding)
};

/// A built subtree as its parent stores it.
struct BuiltChild {
    Bounds3 box;
    int32_t ref = -1;
    int32_t count = 0;
};

double surface_area(const Bounds3& b) {
    if (b.empty()) return 0.0;
    const Vec3d e = b.extent();
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

Bounds3 merged(Bounds3 a, const Bounds3& b) {
    if (!b.empty()) { a.extend(b.min); a.extend(b.max); }
    return a;
}

void write_child(BvhNode& n, int c, const BuiltChild& child) {
    const bool empty = child.box.empty();
    const float inf = std::numeric_limits<float>::infinity();
    n.min_x[c] = empty ? inf : round_down_to_float(child.box.min.x);
    n.min_y[c] = empty ? inf : round_down_to_float(child.box.min.y);
    n.min_z[c] = empty ? inf : round_down_to_float(child.box.min.z);
    n.max_x[c] = empty ? -inf : round_up_to_float(child.box.max.x);
    n.max_y[c] = empty ? -inf : round_up_to_float(child.box.max.y);
    n.max_z[c] = empty ? -inf : round_up_to_float(child.box.max.z);
    n.ref[c] = child.ref;
    n.count[c] = child.count;
}

/// Most SAH bins per axis (BvhBuildOptions::bins is checked against it).
constexpr int kMaxBins = 64;

/// A bin's box, left unconstructed until its first ref arrives (best_split).
union BinSlot {
    BinSlot() {}
    Bounds3 box;
};

struct Split {
    int axis = -1;
    int bin = 0;  ///< refs in bins [0, bin) go left
    double cost = std::numeric_limits<double>::infinity();
};

class Builder {
public:
    Builder(std::vector<BuildRef>& refs, const BvhBuildOptions& o, BvhBuildStats& stats, std::vector<BvhNode>& nodes)
        : refs_(refs), o_(o), stats_(stats), nodes_(nodes) {}

    BuiltChild build(int begin, int end, int depth) {
        Bounds3 box, centroids;
        for (int i = begin; i < end; ++i) { box = merged(box, refs_[size_t(i)].box); centroids.extend(refs_[size_t(i)].centroid); }
        const int count = end - begin;
        if (count <= o_.max_leaf_size) return leaf(box, begin, count);
        // Leaves are small (GPU-friendly); SAH only chooses where to split.
        int mid = -1;
        if (depth < o_.median_split_depth) {
            const Split s = best_split(begin, end, centroids, box);
            if (s.axis >= 0) mid = partition(begin, end, s);
        }
        if (mid <= begin || mid >= end) mid = median_partition(begin, end, centroids);
        return inner(box, begin, mid, end, depth);
    }

private:
    BuiltChild leaf(const Bounds3& box, int begin, int count) {
        ++stats_.leaves;
        stats_.largest_leaf = std::max(stats_.largest_leaf, count);
        return {box, begin, count};
    }

    BuiltChild inner(const Bounds3& box, int begin, int mid, int end, int depth) {
        const int index = int(nodes_.size());
        nodes_.emplace_back();
        stats_.depth = std::max(stats_.depth, depth + 1);
        if (depth + 1 > kBvhMaxDepth)
            throw std::runtime_error("BVH build: depth exceeds kBvhMaxDepth = " + std::to_string(kBvhMaxDepth));
        const BuiltChild l = build(begin, mid, depth + 1);
        const BuiltChild r = build(mid, end, depth + 1);
        write_child(nodes_[size_t(index)], 0, l);
        write_child(nodes_[size_t(index)], 1, r);
        return {box, index, 0};
    }

    /// Binned SAH over the 3 axes: cost = node_cost + (A_L N_L + A_R N_R) / A. One pass
    /// bins every ref on all three axes and keeps its bins for partition(); each bin's box
    /// grows in the same order as with one pass per axis, and sweep() takes the same first
    /// minimum (tests/cpu_reference/bvh/sah_build_test.cpp checks the trees byte for byte).
    Split best_split(int begin, int end, const Bounds3& centroids, const Bounds3& box) {
        const int bins = o_.bins;
        bool active[3];
        double lo[3], extent[3];
        for (int axis = 0; axis < 3; ++axis) {
            active[axis] = centroids.max[axis] > centroids.min[axis];
            lo[axis] = centroids.min[axis];
            extent[axis] = centroids.max[axis] - lo[axis];
        }
        // A bin's box is made empty when its first ref arrives, so that a small node does not
        // pay for clearing every bin (BinSlot leaves its box unconstructed).
        BinSlot bin_box[3][kMaxBins];
        int bin_count[3][kMaxBins] = {};
        for (int i = begin; i < end; ++i) {
            BuildRef& r = refs_[size_t(i)];
            for (int axis = 0; axis < 3; ++axis) {
                if (!active[axis]) continue;
                const int b = std::clamp(int(double(bins) * (r.centroid[axis] - lo[axis]) / extent[axis]), 0, bins - 1);
                r.bin[axis] = uint8_t(b);
                Bounds3& bin = bin_box[axis][b].box;
                if (bin_count[axis][b]++ == 0) bin = Bounds3{};
                bin = merged(bin, r.box);
            }
        }
        Split best;
        const double area = surface_area(box);
        for (int axis = 0; axis < 3; ++axis)
            if (active[axis]) sweep(axis, bin_box[axis], bin_count[axis], area, best);
        return best;
    }

    /// The SAH costs of the splits between bins of one axis, into `best` (first minimum wins).
    /// An empty bin changes neither side, so a split just after one repeats the cost of the
    /// split before it, which never wins a strict `<`: only the splits just after a nonempty
    /// bin are costed, each at the first bin that makes it (the one the full sweep keeps).
    void sweep(int axis, const BinSlot* bin_box, const int* bin_count, double area, Split& best) const {
        int used[kMaxBins], n_used = 0;
        for (int b = 0; b < o_.bins; ++b)
            if (bin_count[b] > 0) used[n_used++] = b;
        // Right-to-left for the right sides (right of split k: used bins k..), then left to right.
        double right_area[kMaxBins];
        int right_count[kMaxBins];
        Bounds3 acc;
        int n = 0;
        for (int k = n_used - 1; k > 0; --k) {
            acc = merged(acc, bin_box[used[k]].box);
            n += bin_count[used[k]];
            right_area[k] = surface_area(acc);
            right_count[k] = n;
        }
        acc = Bounds3{};
        n = 0;
        for (int k = 1; k < n_used; ++k) {
            acc = merged(acc, bin_box[used[k - 1]].box);
            n += bin_count[used[k - 1]];
            const double cost = o_.node_cost + (surface_area(acc) * n + right_area[k] * right_count[k]) / area;
            if (cost < best.cost) best = {axis, used[k - 1] + 1, cost};
        }
    }

    /// The refs left of the split first, by the bins best_split() stored.
    int partition(int begin, int end, const Split& s) {
        auto first = refs_.begin() + begin, last = refs_.begin() + end;
        auto mid = std::partition(first, last, [&](const BuildRef& r) { return r.bin[s.axis] < s.bin; });
        return int(mid - refs_.begin());
    }

    /// Object median along the widest centroid axis: always splits, so the depth stays bounded.
    int median_partition(int begin, int end, const Bounds3& centroids) {
        const Vec3d e = centroids.extent();
        const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
        const int mid = begin + (end - begin) / 2;
        std::nth_element(refs_.begin() + begin, refs_.begin() + mid, refs_.begin() + end,
                         [&](const BuildRef& a, const BuildRef& b) { return a.centroid[axis] < b.centroid[axis]; });
        return mid;
    }

    std::vector<BuildRef>& refs_;
    const BvhBuildOptions& o_;
    BvhBuildStats& stats_;
    std::vector<BvhNode>& nodes_;
};

std::vector<BuildRef> build_refs(const BvhBuildInput& mesh) {
    std::vector<BuildRef> refs(mesh.triangles.size());
    for (size_t i = 0; i < refs.size(); ++i) {
        const Int3 t = mesh.triangles[i];
        Bounds3 b;
        for (int k = 0; k < 3; ++k) b.extend(mesh.vertices[size_t(t[k])]);
        refs[i] = {b, b.center(), int32_t(i), {}};
    }
    return refs;
}

}  // namespace

/// Expected triangle tests of a point query that visits every node and leaf in proportion
/// to its surface area (the SAH's model), for the build statistics.
double bvh_sah_cost(const std::vector<BvhNode>& nodes, double node_cost) {
    auto area = [](const BvhNode& n, int c) {
        const double ex = double(n.max_x[c]) - n.min_x[c], ey = double(n.max_y[c]) - n.min_y[c],
                     ez = double(n.max_z[c]) - n.min_z[c];
        return ex < 0 ? 0.0 : 2.0 * (ex * ey + ey * ez + ez * ex);
    };
    const BvhNode& root = nodes[0];
    Bounds3 rb;
    for (int c = 0; c < 2; ++c)
        if (root.max_x[c] >= root.min_x[c]) {
            rb.extend({root.min_x[c], root.min_y[c], root.min_z[c]});
            rb.extend({root.max_x[c], root.max_y[c], root.max_z[c]});
        }
    const double root_area = std::max(surface_area(rb), 1e-300);
    double cost = node_cost;
    for (const BvhNode& n : nodes)
        for (int c = 0; c < 2; ++c)
            cost += area(n, c) / root_area * (n.count[c] > 0 ? double(n.count[c]) : (n.ref[c] > 0 ? node_cost : 0.0));
    return cost;
}

float round_down_to_float(double x) { return float_below(x); }

float round_up_to_float(double x) { return float_above(x); }

nlohmann::json BvhBuildStats::to_json() const {
    return {{"nodes", nodes}, {"leaves", leaves}, {"depth", depth}, {"largest_leaf", largest_leaf},
            {"sah_cost", sah_cost}, {"build_seconds", seconds}};
}

template <>
BvhView<float> TriangleBvh::view<float>() const {
    return {nodes.data(), packed_float.data(), triangle_index.data(), int(nodes.size()), int(triangle_index.size())};
}

template <>
BvhView<double> TriangleBvh::view<double>() const {
    BvhView<double> v{nodes.data(), packed_double.data(), triangle_index.data(), int(nodes.size()),
                      int(triangle_index.size())};
    // Without the bound (a tree made by hand) the margin is infinite: the brute force.
    v.margin = float_bound ? double_prune_margin(*float_bound) : PruneMargin<double>{INFINITY, 0.0};
    return v;
}

TriangleBvh build_triangle_bvh(const BvhBuildInput& mesh, const BvhBuildOptions& options) {
    if (mesh.triangles.empty()) throw std::invalid_argument("BVH build: mesh '" + mesh.name + "' has no triangles");
    if (mesh.packed_float.size() != mesh.triangles.size() || mesh.packed_double.size() != mesh.triangles.size())
        throw std::invalid_argument("BVH build: mesh '" + mesh.name + "': one packed triangle per triangle expected");
    if (options.max_leaf_size < 1 || options.bins < 2 || options.bins > kMaxBins)
        throw std::invalid_argument("BVH build: max_leaf_size must be >= 1 and bins in [2, 64], got " +
                                    std::to_string(options.max_leaf_size) + " and " + std::to_string(options.bins));
    const auto start = std::chrono::steady_clock::now();
    TriangleBvh bvh;
    bvh.float_bound = mesh.search_bound ? *mesh.search_bound
                                       : float_search_bound(mesh.vertices, mesh.triangles, mesh.packed_double, mesh.packed_float);
    std::vector<BuildRef> refs = build_refs(mesh);
    const int n = int(refs.size());
    bvh.nodes.reserve(size_t(2 * n / std::max(1, options.max_leaf_size) + 1));
    Builder builder(refs, options, bvh.stats, bvh.nodes);
    // Nodes are numbered in pre-order, so the root is node 0; a mesh that fits one leaf gets
    // a root with that leaf and an empty child.
    const BuiltChild root = builder.build(0, n, 0);
    if (root.count > 0) {
        bvh.nodes.emplace_back();
        write_child(bvh.nodes[0], 0, root);
        write_child(bvh.nodes[0], 1, BuiltChild{});
        bvh.stats.depth = 1;
    }
    bvh.triangle_index.resize(size_t(n));
    for (int i = 0; i < n; ++i) bvh.triangle_index[size_t(i)] = refs[size_t(i)].triangle;
    const auto& pf = mesh.packed_float;
    const auto& pd = mesh.packed_double;
    bvh.packed_float.reserve(size_t(n));  // reserve, not resize: no pass that clears them first
    bvh.packed_double.reserve(size_t(n));
    for (int i = 0; i < n; ++i) {
        bvh.packed_float.push_back(pf[size_t(bvh.triangle_index[size_t(i)])]);
        bvh.packed_double.push_back(pd[size_t(bvh.triangle_index[size_t(i)])]);
    }
    bvh.stats.nodes = int(bvh.nodes.size());
    bvh.stats.sah_cost = bvh_sah_cost(bvh.nodes, options.node_cost);
    bvh.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

}  // namespace sdf
