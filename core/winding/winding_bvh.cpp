#include "core/winding/winding_bvh.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <new>
#include <type_traits>

#include "core/parallel/parallel_for.h"

namespace sdf {
namespace {

/// The triangle slots under a child: a leaf's range, or the union of an inner node's
/// children's ranges (the builder partitions in place, so a subtree's slots are contiguous).
struct SlotRange {
    int32_t begin = 0, end = 0;
};

/// What the moments need of one triangle (BVH slot), computed once instead of once per level
/// of the tree, by the same expressions, so the sums below add the same bits in the same order.
struct SlotTerms {
    Vec3d a, b, c;                ///< corners
    Vec3d area_normal;            ///< a_i n_i = (b - a) x (c - a) / 2
    double area = 0;              ///< a_i = |a_i n_i|
    Vec3d weighted_centroid;      ///< (a + b + c) a_i / 3
    Vec3d centroid;               ///< (a + b + c) / 3
};

static_assert(std::is_trivially_destructible_v<SlotTerms>, "slots_ frees its terms without destroying them");

/// Nodes of moments per task of build_winding_bvh's parallel loop (the light ones).
constexpr int64_t kNodesPerTask = 64;
/// Slots under a child from which its moments are a task of their own, scheduled largest first.
constexpr int64_t kHeavySlots = 4096;

class MomentBuilder {
public:
    MomentBuilder(const PreparedMesh& mesh, const TriangleBvh& bvh, std::vector<WindingNode<double>>& out, int threads)
        : bvh_(bvh), out_(out), slots_(static_cast<SlotTerms*>(::operator new(bvh.triangle_index.size() * sizeof(SlotTerms)))),
          ranges_(bvh.nodes.size()), threads_(threads) {
        // Each slot's terms are made by the thread that computes them (12.8 MB at 100k
        // triangles: its pages are first touched on every thread, not zeroed on one first).
        parallel_for(int64_t(bvh.triangle_index.size()), 4096, threads_, [&](int64_t begin, int64_t end) {
            for (int64_t s = begin; s < end; ++s) {
                const Int3& t = mesh.triangles()[size_t(bvh.triangle_index[size_t(s)])];
                SlotTerms& x = *new (&slots_[size_t(s)]) SlotTerms;
                x.a = mesh.vertices()[size_t(t[0])];
                x.b = mesh.vertices()[size_t(t[1])];
                x.c = mesh.vertices()[size_t(t[2])];
                x.area_normal = cross(x.b - x.a, x.c - x.a) * 0.5;
                x.area = length(x.area_normal);
                x.weighted_centroid = (x.a + x.b + x.c) * (x.area / 3.0);
                x.centroid = (x.a + x.b + x.c) / 3.0;
            }
        });
    }

    /// Fills the moments of both children of every node. Each child's moments are summed over
    /// its own slots (not from its children's), so every node is independent of the others:
    /// the slot ranges first (one walk), then all nodes on all threads, the same bits as one.
    ///
    /// A child costs its slots, and pre-order puts the heaviest (a path of n, n/2, n/4, ...
    /// slots) into the first task: the children of kHeavySlots or more go first, largest
    /// first, one per task, then the rest, a node's two children together.
    void run() {
        ranges_of(0);
        auto slots_under = [&](int64_t child) {  // child = 2 node + c
            const SlotRange r = ranges_[size_t(child / 2)][child % 2];
            return int64_t(r.end - r.begin);
        };
        std::vector<int64_t> heavy, light;
        for (int64_t child = 0; child < 2 * int64_t(bvh_.nodes.size()); ++child)
            (slots_under(child) >= kHeavySlots ? heavy : light).push_back(child);
        std::stable_sort(heavy.begin(), heavy.end(), [&](int64_t a, int64_t b) { return slots_under(a) > slots_under(b); });
        auto fill = [&](const std::vector<int64_t>& children, int64_t per_task) {
            parallel_for(int64_t(children.size()), per_task, threads_, [&](int64_t begin, int64_t end) {
                for (int64_t k = begin; k < end; ++k) {
                    const int64_t child = children[size_t(k)];
                    out_[size_t(child / 2)].child[child % 2] = moments_of(ranges_[size_t(child / 2)][child % 2]);
                }
            });
        };
        fill(heavy, 1);
        fill(light, 2 * kNodesPerTask);
    }

private:
    /// Records the slots under both children of `node`; returns the slots under it.
    SlotRange ranges_of(int32_t node) {
        const BvhNode& n = bvh_.nodes[size_t(node)];
        SlotRange under{INT32_MAX, INT32_MIN};
        for (int c = 0; c < 2; ++c) {
            SlotRange r{0, 0};
            if (bvh_child_is_leaf(n, c)) r = {std::max(n.ref[c], 0), std::max(n.ref[c], 0) + n.count[c]};
            else r = ranges_of(n.ref[c]);
            ranges_[size_t(node)][c] = r;
            if (r.end > r.begin) { under.begin = std::min(under.begin, r.begin); under.end = std::max(under.end, r.end); }
        }
        return under.end > under.begin ? under : SlotRange{0, 0};
    }

private:
    WindingMoments<double> moments_of(SlotRange r) const {
        WindingMoments<double> m;
        Vec3d weighted_centroids(0.0);
        for (int32_t s = r.begin; s < r.end; ++s) {
            const SlotTerms& x = slots_[size_t(s)];
            m.area += x.area;
            m.normal_sum += x.area_normal;
            weighted_centroids += x.weighted_centroid;
        }
        if (r.end <= r.begin) return m;
        m.center = m.area > 0 ? weighted_centroids / m.area : slots_[size_t(r.begin)].a;
        // The largest |v - p~|: sqrt is correctly rounded, hence monotone, so the square root
        // of the largest square is the largest of the square roots.
        double radius2 = 0;
        for (int32_t s = r.begin; s < r.end; ++s) {
            const SlotTerms& x = slots_[size_t(s)];
            for (const Vec3d& v : {x.a, x.b, x.c}) radius2 = std::max(radius2, length_squared(v - m.center));
            const Vec3d h = x.centroid - m.center;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) m.second[3 * i + j] += h[i] * x.area_normal[j];
        }
        m.radius = std::sqrt(radius2);
        // Rounding of |v - p~| must not shrink the ball: widen it by a relative 1e-12.
        m.radius *= 1.0 + 1e-12;
        return m;
    }

    const TriangleBvh& bvh_;
    std::vector<WindingNode<double>>& out_;
    struct Free {
        void operator()(SlotTerms* p) const { ::operator delete(p); }  // trivially destructible terms
    };
    std::unique_ptr<SlotTerms[], Free> slots_;      ///< by BVH slot
    std::vector<std::array<SlotRange, 2>> ranges_;  ///< by node: the slots under each child
    int threads_;
};

WindingMoments<float> to_float(const WindingMoments<double>& m) {
    WindingMoments<float> f;
    f.center = Vec3<float>(m.center);
    // The float center is off by up to half an ulp per axis; widen the ball to cover it.
    f.radius = round_up_to_float(m.radius * (1.0 + 1e-6) + length(m.center - Vec3d(f.center)));
    f.area = round_up_to_float(m.area);
    f.normal_sum = Vec3<float>(m.normal_sum);
    for (int i = 0; i < 9; ++i) f.second[i] = float(m.second[i]);
    return f;
}

}  // namespace

WindingBvh build_winding_bvh(const PreparedMesh& mesh, std::shared_ptr<const TriangleBvh> bvh, int threads) {
    const auto start = std::chrono::steady_clock::now();
    WindingBvh w;
    w.bvh = std::move(bvh);
    w.moments.resize(w.bvh->nodes.size());
    threads = resolve_thread_count(threads);
    MomentBuilder(mesh, *w.bvh, w.moments, threads).run();
    w.moments_float.resize(w.moments.size());
    parallel_for(int64_t(w.moments.size()), 1024, threads, [&](int64_t begin, int64_t end) {
        for (int64_t i = begin; i < end; ++i)
            for (int c = 0; c < 2; ++c) w.moments_float[size_t(i)].child[c] = to_float(w.moments[size_t(i)].child[c]);
    });
    w.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return w;
}

WindingBvh build_winding_bvh(const PreparedMesh& mesh) {
    return build_winding_bvh(mesh, mesh.bvh());
}

template <>
WindingView<double> WindingBvh::view<double>(const PreparedMesh& mesh) const {
    const MeshBuffers<double>& b = mesh.buffers<double>();
    return {bvh->nodes.data(), moments.data(), bvh->triangle_index.data(), b.vertices.data(), b.triangles.data(),
            int(bvh->nodes.size()), int(b.triangles.size()), winding_scale(mesh)};
}

template <>
WindingView<float> WindingBvh::view<float>(const PreparedMesh& mesh) const {
    const MeshBuffers<float>& b = mesh.buffers<float>();
    return {bvh->nodes.data(), moments_float.data(), bvh->triangle_index.data(), b.vertices.data(), b.triangles.data(),
            int(bvh->nodes.size()), int(b.triangles.size()), float(winding_scale(mesh))};
}

double winding_scale(const PreparedMesh& mesh) {
    const Bounds3 b = mesh.bounds();
    double s = 0;
    if (b.empty()) return s;
    for (int k = 0; k < 3; ++k) s = std::max(s, std::max(std::abs(b.min[k]), std::abs(b.max[k])));
    return s;
}

}  // namespace sdf
