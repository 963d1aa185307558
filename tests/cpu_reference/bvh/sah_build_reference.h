/// @file sah_build_reference.h
/// @brief The binned SAH build as it was before issue 23 made it faster (one pass per axis,
/// the bin recomputed by the partition), kept only here: the test that the fast build
/// (core/bvh/triangle_bvh.cpp) makes the same tree byte for byte builds both and compares.
/// Why a second builder and not committed checksums: a checksum says only "different"; two
/// trees side by side say at which node, on every mesh the test has, including ones added later.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/bvh/search_bound.h"
#include "core/bvh/triangle_bvh.h"

namespace sdf::test::reference {
/// One triangle as the builder sorts it.
struct BuildRef {
    Bounds3 box;
    Vec3d centroid;
    int32_t triangle;
};

/// A built subtree as its parent stores it.
struct BuiltChild {
    Bounds3 box;
    int32_t ref = -1;
    int32_t count = 0;
};

inline double surface_area(const Bounds3& b) {
    if (b.empty()) return 0.0;
    const Vec3d e = b.extent();
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

inline Bounds3 merged(Bounds3 a, const Bounds3& b) {
    if (!b.empty()) { a.extend(b.min); a.extend(b.max); }
    return a;
}

inline void write_child(BvhNode& n, int c, const BuiltChild& child) {
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
            if (s.axis >= 0) mid = partition(begin, end, s, centroids);
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

    int bin_of(const Vec3d& c, int axis, const Bounds3& centroids) const {
        const double lo = centroids.min[axis], extent = centroids.max[axis] - lo;
        const int b = int(double(o_.bins) * (c[axis] - lo) / extent);
        return std::clamp(b, 0, o_.bins - 1);
    }

    /// Binned SAH over the 3 axes: cost = node_cost + (A_L N_L + A_R N_R) / A.
    Split best_split(int begin, int end, const Bounds3& centroids, const Bounds3& box) const {
        Split best;
        const double area = surface_area(box);
        for (int axis = 0; axis < 3; ++axis) {
            if (!(centroids.max[axis] > centroids.min[axis])) continue;
            Bounds3 bin_box[kMaxBins];
            int bin_count[kMaxBins] = {};
            for (int i = begin; i < end; ++i) {
                const int b = bin_of(refs_[size_t(i)].centroid, axis, centroids);
                bin_box[b] = merged(bin_box[b], refs_[size_t(i)].box);
                ++bin_count[b];
            }
            // Right-to-left sweep for the right sides, then left-to-right for the costs.
            double right_area[kMaxBins] = {};
            int right_count[kMaxBins] = {};
            Bounds3 acc;
            int n = 0;
            for (int b = o_.bins - 1; b > 0; --b) {
                acc = merged(acc, bin_box[b]);
                n += bin_count[b];
                right_area[b] = surface_area(acc);
                right_count[b] = n;
            }
            acc = Bounds3{};
            n = 0;
            for (int b = 1; b < o_.bins; ++b) {
                acc = merged(acc, bin_box[b - 1]);
                n += bin_count[b - 1];
                if (n == 0 || right_count[b] == 0) continue;
                const double cost = o_.node_cost +
                                    (surface_area(acc) * n + right_area[b] * right_count[b]) / area;
                if (cost < best.cost) best = {axis, b, cost};
            }
        }
        return best;
    }

    int partition(int begin, int end, const Split& s, const Bounds3& centroids) {
        auto first = refs_.begin() + begin, last = refs_.begin() + end;
        auto mid = std::partition(first, last, [&](const BuildRef& r) { return bin_of(r.centroid, s.axis, centroids) < s.bin; });
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

inline std::vector<BuildRef> build_refs(const BvhBuildInput& mesh) {
    std::vector<BuildRef> refs(mesh.triangles.size());
    for (size_t i = 0; i < refs.size(); ++i) {
        const Int3 t = mesh.triangles[i];
        Bounds3 b;
        for (int k = 0; k < 3; ++k) b.extend(mesh.vertices[size_t(t[k])]);
        refs[i] = {b, b.center(), int32_t(i)};
    }
    return refs;
}

/// build_triangle_bvh() before issue 23 (everything but stats.seconds and stats.sah_cost,
/// which the fast build computes with the same public bvh_sah_cost()).
inline TriangleBvh build_triangle_bvh_reference(const BvhBuildInput& mesh, const BvhBuildOptions& options = {}) {
    if (mesh.triangles.empty()) throw std::invalid_argument("BVH build: mesh '" + mesh.name + "' has no triangles");
    if (mesh.packed_float.size() != mesh.triangles.size() || mesh.packed_double.size() != mesh.triangles.size())
        throw std::invalid_argument("BVH build: mesh '" + mesh.name + "': one packed triangle per triangle expected");
    if (options.max_leaf_size < 1 || options.bins < 2 || options.bins > kMaxBins)
        throw std::invalid_argument("BVH build: max_leaf_size must be >= 1 and bins in [2, 64], got " +
                                    std::to_string(options.max_leaf_size) + " and " + std::to_string(options.bins));
    const auto start = std::chrono::steady_clock::now();
    TriangleBvh bvh;
    bvh.float_bound = float_search_bound(mesh.vertices, mesh.triangles, mesh.packed_double, mesh.packed_float);
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
    bvh.packed_float.resize(size_t(n));
    bvh.packed_double.resize(size_t(n));
    for (int i = 0; i < n; ++i) {
        bvh.packed_float[size_t(i)] = pf[size_t(bvh.triangle_index[size_t(i)])];
        bvh.packed_double[size_t(i)] = pd[size_t(bvh.triangle_index[size_t(i)])];
    }
    bvh.stats.nodes = int(bvh.nodes.size());
    bvh.stats.sah_cost = bvh_sah_cost(bvh.nodes, options.node_cost);
    bvh.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

}  // namespace sdf::test::reference
