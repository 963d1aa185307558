#include "core/mesh/self_intersections.h"

#include <algorithm>
#include <chrono>
#include <set>

#include "core/mesh/triangle_intersection.h"
#include "core/parallel/parallel_for.h"

namespace sdf {
namespace {

/// A child of a BVH node as the pair descent sees it: its box and what it refers to.
struct Child {
    float lo[3], hi[3];
    int32_t ref, count;
    bool leaf;
};

Child child_of(const BvhNode& n, int c) {
    return {{n.min_x[c], n.min_y[c], n.min_z[c]}, {n.max_x[c], n.max_y[c], n.max_z[c]}, n.ref[c], n.count[c],
            bvh_child_is_leaf(n, c)};
}

bool boxes_overlap(const Child& a, const Child& b) {
    for (int k = 0; k < 3; ++k)
        if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
    return true;
}

double volume(const Child& c) { return double(c.hi[0] - c.lo[0]) * double(c.hi[1] - c.lo[1]) * double(c.hi[2] - c.lo[2]); }

/// Which child a pair descent opens: the inner one, the larger when both are.
bool opens_first(const Child& a, const Child& b) { return !a.leaf && (b.leaf || volume(a) >= volume(b)); }

/// A triangle's box in double: its corners' min and max, exact.
struct TriangleBox {
    double lo[3], hi[3];
};

bool boxes_overlap(const TriangleBox& a, const TriangleBox& b) {
    for (int k = 0; k < 3; ++k)
        if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return false;
    return true;
}

/// The boxes of the triangles in BVH slot order.
std::vector<TriangleBox> triangle_boxes(const PreparedMesh& mesh, const TriangleBvh& bvh) {
    std::vector<TriangleBox> boxes(bvh.triangle_index.size());
    for (size_t s = 0; s < boxes.size(); ++s) {
        const Int3 t = mesh.triangles()[size_t(bvh.triangle_index[s])];
        const Vec3d& a = mesh.vertices()[size_t(t.x)];
        const Vec3d& b = mesh.vertices()[size_t(t.y)];
        const Vec3d& c = mesh.vertices()[size_t(t.z)];
        for (int k = 0; k < 3; ++k) {
            boxes[s].lo[k] = std::min({a[k], b[k], c[k]});
            boxes[s].hi[k] = std::max({a[k], b[k], c[k]});
        }
    }
    return boxes;
}

class PairDescent {
public:
    PairDescent(const PreparedMesh& mesh, const TriangleBvh& bvh, const std::vector<TriangleBox>& boxes,
                std::vector<std::pair<int, int>>& pairs)
        : mesh_(mesh), bvh_(bvh), boxes_(boxes), pairs_(pairs) {}

    /// Pairs within the subtree of `c`.
    void within(const Child& c) {
        if (c.leaf) {
            for (int32_t i = c.ref; i < c.ref + c.count; ++i)
                for (int32_t j = i + 1; j < c.ref + c.count; ++j) test(i, j);
            return;
        }
        const BvhNode& n = bvh_.nodes[size_t(c.ref)];
        const Child l = child_of(n, 0), r = child_of(n, 1);
        within(l);
        within(r);
        between(l, r);
    }

    /// Pairs with one triangle under `a` and one under `b` (disjoint subtrees).
    void between(const Child& a, const Child& b) {
        if (!boxes_overlap(a, b)) return;
        if (a.leaf && b.leaf) {
            for (int32_t i = a.ref; i < a.ref + a.count; ++i)
                for (int32_t j = b.ref; j < b.ref + b.count; ++j) test(i, j);
            return;
        }
        const bool open_a = opens_first(a, b);
        const Child& open = open_a ? a : b;
        const Child& keep = open_a ? b : a;
        const BvhNode& n = bvh_.nodes[size_t(open.ref)];
        between(child_of(n, 0), keep);
        between(child_of(n, 1), keep);
    }

private:
    /// The exact test, for triangles whose own boxes overlap (a leaf's box holds several, and
    /// triangles with disjoint boxes cannot meet: the box test is exact and closed).
    void test(int32_t slot_a, int32_t slot_b) {
        if (!boxes_overlap(boxes_[size_t(slot_a)], boxes_[size_t(slot_b)])) return;
        const int ta = bvh_.triangle_index[size_t(slot_a)], tb = bvh_.triangle_index[size_t(slot_b)];
        const Int3 ia = mesh_.triangles()[size_t(ta)], ib = mesh_.triangles()[size_t(tb)];
        const Vec3d a[3] = {mesh_.vertices()[size_t(ia.x)], mesh_.vertices()[size_t(ia.y)], mesh_.vertices()[size_t(ia.z)]};
        const Vec3d b[3] = {mesh_.vertices()[size_t(ib.x)], mesh_.vertices()[size_t(ib.y)], mesh_.vertices()[size_t(ib.z)]};
        if (triangles_intersect(a, ia, b, ib)) pairs_.push_back({std::min(ta, tb), std::max(ta, tb)});
    }

    const PreparedMesh& mesh_;
    const TriangleBvh& bvh_;
    const std::vector<TriangleBox>& boxes_;
    std::vector<std::pair<int, int>>& pairs_;
};

/// One piece of the descent: the pairs within `a`'s subtree (`within`), or between the
/// disjoint subtrees of `a` and `b`.
struct DescentTask {
    Child a, b;
    bool within;
};

/// The descent's top levels, opened breadth-first into at least `target` independent tasks
/// (or as many as the tree has): each pair of triangles lies in exactly one of them, so
/// they can run on any threads in any order.
std::vector<DescentTask> descent_tasks(const TriangleBvh& bvh, size_t target) {
    std::vector<DescentTask> tasks, open;
    const BvhNode& root = bvh.nodes[0];
    open.push_back({child_of(root, 0), {}, true});
    open.push_back({child_of(root, 1), {}, true});
    open.push_back({child_of(root, 0), child_of(root, 1), false});
    while (!open.empty() && tasks.size() + open.size() < target) {
        std::vector<DescentTask> next;
        for (const DescentTask& t : open) {
            if (t.within) {
                if (t.a.leaf) { tasks.push_back(t); continue; }
                const BvhNode& n = bvh.nodes[size_t(t.a.ref)];
                const Child l = child_of(n, 0), r = child_of(n, 1);
                next.push_back({l, {}, true});
                next.push_back({r, {}, true});
                next.push_back({l, r, false});
            } else {
                if (!boxes_overlap(t.a, t.b)) continue;
                if (t.a.leaf && t.b.leaf) { tasks.push_back(t); continue; }
                const bool open_a = opens_first(t.a, t.b);  // as PairDescent::between opens it
                const Child& opened = open_a ? t.a : t.b;
                const Child& kept = open_a ? t.b : t.a;
                const BvhNode& n = bvh.nodes[size_t(opened.ref)];
                next.push_back({child_of(n, 0), kept, false});
                next.push_back({child_of(n, 1), kept, false});
            }
        }
        open.swap(next);
    }
    tasks.insert(tasks.end(), open.begin(), open.end());
    return tasks;
}

}  // namespace

SelfIntersections find_self_intersections(const PreparedMesh& mesh, const TriangleBvh& bvh, const std::vector<int>& shell_of,
                                          int threads) {
    const auto start = std::chrono::steady_clock::now();
    SelfIntersections out;
    if (!bvh.nodes.empty()) {
        // The pairs of a CAD face's fan all meet at its centre: a 13,000-triangle box takes
        // about a second of exact tests, so the descent runs on every core. The sorted list
        // is the same whatever the thread count.
        threads = resolve_thread_count(threads);
        const std::vector<TriangleBox> boxes = triangle_boxes(mesh, bvh);
        const std::vector<DescentTask> tasks = descent_tasks(bvh, size_t(64) * size_t(threads));
        std::vector<std::vector<std::pair<int, int>>> found(tasks.size());
        parallel_for(int64_t(tasks.size()), 1, threads, [&](int64_t begin, int64_t end) {
            for (int64_t k = begin; k < end; ++k) {
                const DescentTask& t = tasks[size_t(k)];
                PairDescent descent(mesh, bvh, boxes, found[size_t(k)]);
                if (t.within) descent.within(t.a);
                else descent.between(t.a, t.b);
            }
        });
        for (const auto& f : found) out.pairs.insert(out.pairs.end(), f.begin(), f.end());
    }
    std::sort(out.pairs.begin(), out.pairs.end());
    std::set<std::pair<int, int>> shell_pairs;
    for (const auto& [a, b] : out.pairs) {
        const int sa = shell_of.empty() ? 0 : shell_of[size_t(a)], sb = shell_of.empty() ? 0 : shell_of[size_t(b)];
        if (sa == sb) ++out.within_shell;
        else { ++out.between_shells; shell_pairs.insert({std::min(sa, sb), std::max(sa, sb)}); }
    }
    out.overlapping_shell_pairs = int(shell_pairs.size());
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

}  // namespace sdf
