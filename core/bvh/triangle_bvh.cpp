#include "core/bvh/triangle_bvh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/bvh/search_bound.h"
#include "core/parallel/parallel_for.h"
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

/// a grown by b. For a nonempty b (b.min <= b.max) this has the bits of a.extend(b.min) then
/// a.extend(b.max): the comparisons keep the later of equal values (+0 after -0), and b's
/// corners, where equal on an axis, are the same bits. Every merge order below is the order
/// of the refs, so a box is the same bits however the work is split (parallel_bins()).
Bounds3 merged(Bounds3 a, const Bounds3& b) {
    if (!b.empty()) { a.min = component_min(a.min, b.min); a.max = component_max(a.max, b.max); }
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

/// The bins of the three axes over a range of refs: each bin's box and count, made when its
/// first ref arrives (`used`), so that a small node pays neither for clearing every bin nor
/// for looking at every bin in sweep().
struct Bins {
    BinSlot box[3][kMaxBins];
    int count[3][kMaxBins];
    uint64_t used[3] = {0, 0, 0};  ///< bit b: bin b holds a ref
};

/// Where the centroids of a node lie, per axis, for its bins.
struct BinGrid {
    bool active[3];
    double lo[3], extent[3];
};

/// Refs of a node above which its box and bins are computed on several threads, in chunks of
/// kBinChunk refs, and merged in chunk order (the order of the refs, so the same bits).
constexpr int kParallelBinning = 8192;
constexpr int kBinChunk = 8192;
/// Fewest refs a subtree task gets (below it a task costs less than starting one).
constexpr int kMinTaskRefs = 2048;
/// Refs of a node from which its refs are binned into two sets of bins (bin_range()).
constexpr int kTwoBinSets = 256;

/// A subtree below the top of the tree, built on its own by one thread into its own nodes,
/// numbered from 0 in pre-order like the whole tree's (its root, an inner node, is 0).
struct SubtreeTask {
    int begin = 0, end = 0, depth = 0;
    std::vector<BvhNode> nodes;
    BvhBuildStats stats;
};

/// Marks a child of a top node whose subtree is a task (BuiltChild::ref: the task's index);
/// a built child's count is never negative.
constexpr int32_t kTaskChild = -1;

/// What the top of the tree makes of one node: a leaf, a task, or a split at `mid`.
struct TopSplit {
    enum Kind { Leaf, Task, Inner } kind = Leaf;
    Bounds3 box;
    int mid = 0;
};

/// Top-down binned SAH: build() is the one-threaded recursion (the tree's nodes in
/// pre-order). split_top() splits one node of the top of the tree (build_top(), which runs
/// it on many nodes at once), binning on `threads` threads when the node has more than
/// kParallelBinning refs. Every split is the one the recursion makes, so the tree is the same
/// bytes at any thread count (tests/cpu_reference/bvh/sah_build_test.cpp).
class Builder {
public:
    Builder(DefaultInitVector<BuildRef>& refs, const BvhBuildOptions& o, BvhBuildStats& stats, std::vector<BvhNode>& nodes,
            int threads = 1)
        : refs_(refs), o_(o), stats_(stats), nodes_(nodes), threads_(threads) {}

    BuiltChild build(int begin, int end, int depth) {
        Bounds3 box, centroids;
        bounds(begin, end, box, centroids);
        const int count = end - begin;
        if (count <= o_.max_leaf_size) return leaf(box, begin, count);
        return inner(box, begin, split(begin, end, depth, box, centroids), end, depth);
    }

    /// build()'s first step on one node of the top: a leaf, a task (at most `grain` refs) or
    /// the split (its refs partitioned); nothing recorded in the statistics or the nodes.
    TopSplit split_top(int begin, int end, int depth, int grain) {
        TopSplit t;
        Bounds3 centroids;
        bounds(begin, end, t.box, centroids);
        const int count = end - begin;
        if (count <= o_.max_leaf_size) return t;
        if (count <= grain) {
            t.kind = TopSplit::Task;
            return t;
        }
        t.kind = TopSplit::Inner;
        t.mid = split(begin, end, depth, t.box, centroids);
        return t;
    }

private:
    bool parallel(int count) const { return threads_ > 1 && count > kParallelBinning; }

    /// Where a node of more than max_leaf_size refs splits, its refs partitioned there.
    int split(int begin, int end, int depth, const Bounds3& box, const Bounds3& centroids) {
        // Leaves are small (GPU-friendly); SAH only chooses where to split.
        int mid = -1;
        if (depth < o_.median_split_depth) {
            const Split s = best_split(begin, end, centroids, box);
            if (s.axis >= 0) mid = partition(begin, end, s);
        }
        if (mid <= begin || mid >= end) mid = median_partition(begin, end, centroids);
        return mid;
    }

    /// The node's box and the box of its refs' centroids (one thread: a pass this short
    /// gains nothing from more).
    void bounds(int begin, int end, Bounds3& box, Bounds3& centroids) const {
        for (int i = begin; i < end; ++i) {
            box = merged(box, refs_[size_t(i)].box);
            centroids.extend(refs_[size_t(i)].centroid);
        }
    }

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

    /// Bins refs [begin, end) on every active axis into `bins` (whose boxes start unmade: a
    /// bin's box is made empty when its first ref arrives, so that a small node does not pay
    /// for clearing every bin), and keeps each ref's bins for partition().
    void bin_range(int begin, int end, const BinGrid& g, Bins& bins) const {
        const int n_bins = o_.bins;
        const auto add = [&](int i, Bins& to) {
            BuildRef& r = refs_[size_t(i)];
            for (int axis = 0; axis < 3; ++axis) {
                if (!g.active[axis]) continue;
                const int b = std::clamp(int(double(n_bins) * (r.centroid[axis] - g.lo[axis]) / g.extent[axis]), 0, n_bins - 1);
                r.bin[axis] = uint8_t(b);
                Bounds3& bin = to.box[axis][b].box;
                const uint64_t bit = uint64_t(1) << b;
                if (!(to.used[axis] & bit)) {
                    to.used[axis] |= bit;
                    to.count[axis][b] = 1;
                    bin = r.box;
                } else {
                    ++to.count[axis][b];
                    bin = merged(bin, r.box);
                }
            }
        };
        if (end - begin < kTwoBinSets) {
            for (int i = begin; i < end; ++i) add(i, bins);
            return;
        }
        // Neighbouring refs mostly fall into the same bins, and each update of a bin's box
        // waits for the one before it; two sets of bins, alternate refs, halve those chains.
        // A bin's box enters the SAH through its surface area only, so the order in which
        // it grows (which of +0 and -0 it keeps) does not matter, unlike a node's box.
        Bins odd;
        int i = begin;
        for (; i + 1 < end; i += 2) { add(i, bins); add(i + 1, odd); }
        if (i < end) add(i, bins);
        merge_bins(bins, odd);
    }

    /// Adds the bins of `from` to `into`, whose refs came first.
    void merge_bins(Bins& into, const Bins& from) const {
        for (int axis = 0; axis < 3; ++axis)
            for (uint64_t m = from.used[axis]; m != 0; m &= m - 1) {
                const int b = __builtin_ctzll(m);
                Bounds3& bin = into.box[axis][b].box;
                if (into.used[axis] & (uint64_t(1) << b)) {
                    bin = merged(bin, from.box[axis][b].box);
                    into.count[axis][b] += from.count[axis][b];
                } else {
                    bin = from.box[axis][b].box;
                    into.count[axis][b] = from.count[axis][b];
                }
            }
        for (int axis = 0; axis < 3; ++axis) into.used[axis] |= from.used[axis];
    }

    /// Binned SAH over the 3 axes: cost = node_cost + (A_L N_L + A_R N_R) / A. One pass
    /// bins every ref on all three axes and keeps its bins for partition(); each bin's box
    /// grows in the same order as with one pass per axis, and sweep() takes the same first
    /// minimum (tests/cpu_reference/bvh/sah_build_test.cpp checks the trees byte for byte).
    Split best_split(int begin, int end, const Bounds3& centroids, const Bounds3& box) {
        BinGrid g;
        for (int axis = 0; axis < 3; ++axis) {
            g.active[axis] = centroids.max[axis] > centroids.min[axis];
            g.lo[axis] = centroids.min[axis];
            g.extent[axis] = centroids.max[axis] - g.lo[axis];
        }
        Bins bins;
        if (!parallel(end - begin)) {
            bin_range(begin, end, g, bins);
        } else {
            const int chunks = (end - begin + kBinChunk - 1) / kBinChunk;
            std::vector<Bins> part(static_cast<size_t>(chunks));
            parallel_for(chunks, 1, threads_, [&](int64_t k0, int64_t k1) {
                for (int64_t k = k0; k < k1; ++k)
                    bin_range(begin + int(k) * kBinChunk, std::min(end, begin + int(k + 1) * kBinChunk), g, part[size_t(k)]);
            });
            for (const Bins& p : part) merge_bins(bins, p);
        }
        Split best;
        const double area = surface_area(box);
        for (int axis = 0; axis < 3; ++axis)
            if (g.active[axis]) sweep(axis, bins.box[axis], bins.count[axis], bins.used[axis], area, best);
        return best;
    }

    /// The SAH costs of the splits between bins of one axis, into `best` (first minimum wins).
    /// An empty bin changes neither side, so a split just after one repeats the cost of the
    /// split before it, which never wins a strict `<`: only the splits just after a nonempty
    /// bin are costed, each at the first bin that makes it (the one the full sweep keeps).
    void sweep(int axis, const BinSlot* bin_box, const int* bin_count, uint64_t used_bins, double area, Split& best) const {
        int used[kMaxBins], n_used = 0;
        for (uint64_t m = used_bins; m != 0; m &= m - 1) used[n_used++] = __builtin_ctzll(m);
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

    DefaultInitVector<BuildRef>& refs_;
    const BvhBuildOptions& o_;
    BvhBuildStats& stats_;
    std::vector<BvhNode>& nodes_;
    int threads_;
};

DefaultInitVector<BuildRef> build_refs(const BvhBuildInput& mesh, int threads) {
    DefaultInitVector<BuildRef> refs(mesh.triangles.size());
    parallel_for(int64_t(refs.size()), 8192, threads, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) {
            const Int3 t = mesh.triangles[size_t(i)];
            Bounds3 b;
            for (int k = 0; k < 3; ++k) b.extend(mesh.vertices[size_t(t[k])]);
            refs[size_t(i)] = {b, b.center(), int32_t(i), {}};
        }
    });
    return refs;
}

/// Appends top node `t` and, in pre-order, everything below it: its top children and the
/// tasks' nodes, whose inner-child references move by where they land. Returns t's index.
int32_t splice(const std::vector<BvhNode>& top, int32_t t, std::vector<SubtreeTask>& tasks, std::vector<BvhNode>& out) {
    const int32_t at = int32_t(out.size());
    out.push_back(top[size_t(t)]);
    for (int c = 0; c < 2; ++c) {
        const int32_t count = top[size_t(t)].count[c], ref = top[size_t(t)].ref[c];
        int32_t moved = ref;
        if (count == kTaskChild) {
            std::vector<BvhNode>& nodes = tasks[size_t(ref)].nodes;
            moved = int32_t(out.size());
            for (BvhNode& node : nodes) {
                for (int k = 0; k < 2; ++k)
                    if (node.count[k] == 0 && node.ref[k] > 0) node.ref[k] += moved;
                out.push_back(node);
            }
            std::vector<BvhNode>().swap(nodes);
        } else if (count == 0 && ref > 0) {
            moved = splice(top, ref, tasks, out);
        }
        out[size_t(at)].ref[c] = moved;
        out[size_t(at)].count[c] = count == kTaskChild ? 0 : count;
    }
    return at;
}

/// The top of the tree, level by level, into `top` (children referenced by index; splice()
/// puts them in pre-order): a level's nodes of more than kParallelBinning refs one after
/// another, each binned on all threads, then its other nodes side by side, one thread each
/// (they own disjoint ranges of refs). A node of at most `grain` refs becomes a SubtreeTask.
/// Returns the root's child.
BuiltChild build_top(DefaultInitVector<BuildRef>& refs, const BvhBuildOptions& o, BvhBuildStats& stats, std::vector<BvhNode>& top,
                     std::vector<SubtreeTask>& tasks, int grain, int threads) {
    struct Pending {
        int begin, end, depth;
        int32_t parent;  ///< its node in `top`, -1 for the root
        int side;        ///< which child of it
    };
    std::vector<Pending> level{{0, int(refs.size()), 0, -1, 0}};
    BuiltChild root;
    while (!level.empty()) {
        std::vector<TopSplit> done(level.size());
        std::vector<size_t> small;
        for (size_t k = 0; k < level.size(); ++k) {
            const Pending& p = level[k];
            if (p.end - p.begin > kParallelBinning) done[k] = Builder(refs, o, stats, top, threads).split_top(p.begin, p.end, p.depth, grain);
            else small.push_back(k);
        }
        parallel_for(int64_t(small.size()), 1, threads, [&](int64_t k0, int64_t k1) {
            for (int64_t k = k0; k < k1; ++k) {
                const Pending& p = level[small[size_t(k)]];
                done[small[size_t(k)]] = Builder(refs, o, stats, top).split_top(p.begin, p.end, p.depth, grain);
            }
        });
        std::vector<Pending> next;
        for (size_t k = 0; k < level.size(); ++k) {
            const Pending& p = level[k];
            const TopSplit& t = done[k];
            const int count = p.end - p.begin;
            BuiltChild child{t.box, p.begin, count};  // a leaf
            if (t.kind == TopSplit::Leaf) {
                ++stats.leaves;
                stats.largest_leaf = std::max(stats.largest_leaf, count);
            } else if (t.kind == TopSplit::Task) {
                tasks.push_back({p.begin, p.end, p.depth, {}, {}});
                child = {t.box, int32_t(tasks.size() - 1), kTaskChild};
            } else {
                stats.depth = std::max(stats.depth, p.depth + 1);
                if (p.depth + 1 > kBvhMaxDepth)
                    throw std::runtime_error("BVH build: depth exceeds kBvhMaxDepth = " + std::to_string(kBvhMaxDepth));
                child = {t.box, int32_t(top.size()), 0};
                top.emplace_back();
                next.push_back({p.begin, t.mid, p.depth + 1, child.ref, 0});
                next.push_back({t.mid, p.end, p.depth + 1, child.ref, 1});
            }
            if (p.parent < 0) root = child;
            else write_child(top[size_t(p.parent)], p.side, child);
        }
        level = std::move(next);
    }
    return root;
}

/// The nodes of the whole tree in pre-order, and the root's child (a leaf if the mesh fits
/// one). On one thread, one recursion; on several, the top of the tree first (build_top)
/// down to subtrees of about n / (8 threads) refs, those subtrees on all threads, then
/// spliced in pre-order.
BuiltChild build_nodes(DefaultInitVector<BuildRef>& refs, const BvhBuildOptions& o, BvhBuildStats& stats,
                       std::vector<BvhNode>& nodes) {
    const int n = int(refs.size());
    const int threads = resolve_thread_count(o.threads);
    const int grain = std::max(kMinTaskRefs, n / (8 * threads));
    if (threads <= 1 || n <= grain) return Builder(refs, o, stats, nodes).build(0, n, 0);
    std::vector<SubtreeTask> tasks;
    std::vector<BvhNode> top;
    const BuiltChild root = build_top(refs, o, stats, top, tasks, grain, threads);
    if (root.count > 0) return root;  // one leaf (max_leaf_size >= n); n > grain: never a task
    parallel_for(int64_t(tasks.size()), 1, threads, [&](int64_t k0, int64_t k1) {
        for (int64_t k = k0; k < k1; ++k) {
            SubtreeTask& t = tasks[size_t(k)];
            Builder(refs, o, t.stats, t.nodes).build(t.begin, t.end, t.depth);
        }
    });
    size_t total = top.size();
    for (const SubtreeTask& t : tasks) {
        total += t.nodes.size();
        stats.leaves += t.stats.leaves;
        stats.largest_leaf = std::max(stats.largest_leaf, t.stats.largest_leaf);
        stats.depth = std::max(stats.depth, t.stats.depth);
    }
    nodes.reserve(total);
    splice(top, 0, tasks, nodes);
    return root;
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
    const int threads = resolve_thread_count(options.threads);
    DefaultInitVector<BuildRef> refs = build_refs(mesh, threads);
    const int n = int(refs.size());
    bvh.nodes.reserve(size_t(2 * n / std::max(1, options.max_leaf_size) + 1));
    // Nodes are numbered in pre-order, so the root is node 0; a mesh that fits one leaf gets
    // a root with that leaf and an empty child.
    const BuiltChild root = build_nodes(refs, options, bvh.stats, bvh.nodes);
    if (root.count > 0) {
        bvh.nodes.emplace_back();
        write_child(bvh.nodes[0], 0, root);
        write_child(bvh.nodes[0], 1, BuiltChild{});
        bvh.stats.depth = 1;
    }
    // The slots' triangles and their packed constants, gathered on every thread.
    bvh.triangle_index.resize(size_t(n));
    bvh.packed_float.resize(size_t(n));
    bvh.packed_double.resize(size_t(n));
    parallel_for(n, 8192, threads, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) {
            const int32_t t = refs[size_t(i)].triangle;
            bvh.triangle_index[size_t(i)] = t;
            bvh.packed_float[size_t(i)] = mesh.packed_float[size_t(t)];
            bvh.packed_double[size_t(i)] = mesh.packed_double[size_t(t)];
        }
    });
    bvh.stats.nodes = int(bvh.nodes.size());
    bvh.stats.sah_cost = bvh_sah_cost(bvh.nodes, options.node_cost);
    bvh.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

}  // namespace sdf
