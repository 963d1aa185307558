/// @file lbvh_steps.h
/// @brief The per-element steps of the BVH built on the GPU, written once for the host
/// emulation (core/bvh/lbvh.cpp) and the CUDA build (cuda/bvh/device_bvh_build.cu), so both
/// produce the same tree, boxes and winding moments bit for bit.
///
/// Two builders make the same binary tree over the triangles (n leaves, n - 1 internal
/// nodes, the root internal node 0), from the triangles sorted by the Morton key of their
/// centroids:
/// - LBVH: Karras, "Maximizing Parallelism in the Construction of BVHs, Octrees, and k-d
///   Trees" (HPG 2012): internal node i finds its key range and split from its neighbours'
///   keys alone (section 4); equal keys are told apart by their positions.
/// - PLOC: Meister & Bittner, "Parallel Locally-Ordered Clustering for Bounding Volume
///   Hierarchy Construction" (IEEE TVCG 2018): clusters in Morton order each find their
///   nearest neighbour (the smallest merged box surface) within `radius` positions; mutual
///   nearest neighbours merge; the rest are compacted; repeat until one cluster. SAH-like
///   quality at LBVH-like speed.
///
/// The flat layout (bvh_node.h) then needs: leaves of at most `max_leaf` triangles (a node
/// whose subtree holds <= max_leaf triangles becomes one leaf of its parent: "kept" nodes
/// are those with more, a connected top of the tree, numbered by a prefix sum so the root
/// stays 0), leaves as contiguous slot ranges (slots = the tree's left-to-right leaf order),
/// float boxes rounded outward from the double triangle bounds, and the fast winding
/// number's moments per child (winding_moments.h). Both come from one bottom-up pass
/// (Karras section 4, with atomics: the second child to arrive at a node merges both and
/// moves up), and an exact radius pass (each leaf raises its ancestors' radii with an
/// atomic max).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "kernels/bvh/bvh_node.h"
#include "kernels/core/directed_rounding.h"
#include "kernels/core/morton.h"
#include "kernels/core/vec3.h"
#include "kernels/winding/winding_moments.h"

namespace sdf {

/// A child in the binary tree: >= 0 an internal node, < 0 the leaf of sorted position ~code.
SDF_CPU_GPU SDF_INLINE bool lbvh_is_leaf(int32_t code) { return code < 0; }

/// Plain pointers to the build's arrays (host or device). n triangles, n - 1 internal nodes.
struct LbvhArrays {
    int n = 0;
    int max_leaf = 4;
    const Vec3d* vertices = nullptr;
    const Int3* triangles = nullptr;
    const uint64_t* keys = nullptr;    ///< Morton keys, sorted (ties in triangle order)
    const int32_t* sorted = nullptr;   ///< sorted position -> triangle
    // The binary tree (per internal node, except leaf_parent and leaf_slot: per leaf).
    int32_t* left = nullptr;           ///< child codes (lbvh_is_leaf)
    int32_t* right = nullptr;
    int32_t* parent = nullptr;         ///< -1 for the root (node 0)
    int32_t* leaf_parent = nullptr;
    int32_t* count = nullptr;          ///< triangles under the node
    int32_t* first = nullptr;          ///< its first slot
    int32_t* leaf_slot = nullptr;      ///< the leaf's slot
    int32_t* order = nullptr;          ///< slot -> triangle (the output's triangle_index)
    // The flat layout.
    int32_t* kept_index = nullptr;     ///< per internal node: its node index when kept (prefix sum)
    uint32_t* arrivals = nullptr;      ///< per internal node: children arrived (bottom-up pass)
    BvhNode* nodes = nullptr;          ///< per kept node
    WindingNode<double>* moments = nullptr;  ///< per kept node
    Vec3d* weighted = nullptr;         ///< per kept node x 2: sum a_i c_i of each child
};

// --- Host/device primitives ------------------------------------------------------------

SDF_CPU_GPU SDF_INLINE int lbvh_clz64(uint64_t x) {
#if SDF_IS_GPU_CODE
    return __clzll((long long)x);
#else
    return x == 0 ? 64 : __builtin_clzll(x);
#endif
}

SDF_CPU_GPU SDF_INLINE int lbvh_clz32(uint32_t x) {
#if SDF_IS_GPU_CODE
    return __clz(int(x));
#else
    return x == 0 ? 32 : __builtin_clz(x);
#endif
}

/// Returns the old value. The device build passes real atomics; the host emulation runs
/// the elements one after another, where a plain update is the same.
SDF_CPU_GPU SDF_INLINE uint32_t lbvh_atomic_add(uint32_t* p, uint32_t v) {
#if SDF_IS_GPU_CODE
    return atomicAdd(p, v);
#else
    const uint32_t old = *p;
    *p += v;
    return old;
#endif
}

/// *p = max(*p, v) for v >= 0 (non-negative doubles order as their bit patterns).
SDF_CPU_GPU SDF_INLINE void lbvh_atomic_max(double* p, double v) {
#if SDF_IS_GPU_CODE
    // The value only grows, so a stale read is at most it: skipping the atomic where v does
    // not exceed it loses nothing, and spares the top nodes, which every leaf below them
    // raises, most of their serialised atomics.
    if (!(v > *p)) return;
    atomicMax(reinterpret_cast<unsigned long long*>(p), static_cast<unsigned long long>(__double_as_longlong(v)));
#else
    if (v > *p) *p = v;
#endif
}

/// Makes this element's writes visible before it signals its arrival (device only).
SDF_CPU_GPU SDF_INLINE void lbvh_fence() {
#if SDF_IS_GPU_CODE
    __threadfence();
#endif
}

/// A load that sees another thread's fenced writes (bypasses the non-coherent L1).
template <typename T>
SDF_CPU_GPU SDF_INLINE T lbvh_load(const T* p) {
#if SDF_IS_GPU_CODE
    return __ldcg(p);
#else
    return *p;
#endif
}

// --- Step 1: keys ------------------------------------------------------------------------

/// The Morton key of triangle t's centroid (the centre of its double bounds, as the SAH
/// builder's) in the cube [lo, lo + 1 / inv_extent).
SDF_CPU_GPU SDF_INLINE uint64_t lbvh_triangle_key(const Vec3d* vertices, const Int3* triangles, int t, const Vec3d& lo,
                                                  double inv_extent) {
    const Int3 tri = triangles[t];
    const Vec3d a = vertices[tri.x], b = vertices[tri.y], c = vertices[tri.z];
    // As Bounds3::extend and center(): min/max per axis, then (min + max) / 2.
    Vec3d centre;
    for (int x = 0; x < 3; ++x) {
        double mn = a[x], mx = a[x];
        mn = b[x] < mn ? b[x] : mn; mx = b[x] > mx ? b[x] : mx;
        mn = c[x] < mn ? c[x] : mn; mx = c[x] > mx ? c[x] : mx;
        centre[x] = (mn + mx) * 0.5;
    }
    return morton_key_of_point(centre.x, centre.y, centre.z, lo.x, lo.y, lo.z, inv_extent);
}

// --- Step 2: the radix tree (Karras, section 4) ----------------------------------------

/// Length of the common prefix of the keys at slots i and j (-1 outside [0, n)); equal
/// keys continue with the slots' own bits.
SDF_CPU_GPU SDF_INLINE int lbvh_delta(const LbvhArrays& a, int i, int64_t j) {
    if (j < 0 || j >= a.n) return -1;
    const uint64_t ki = a.keys[i], kj = a.keys[j];
    if (ki != kj) return lbvh_clz64(ki ^ kj);
    return 64 + lbvh_clz32(uint32_t(i) ^ uint32_t(j));
}

/// Internal node i of the radix tree: its children, their parent links, its count and first
/// slot (the LBVH keeps the sorted order: slot = sorted position).
SDF_CPU_GPU SDF_INLINE void lbvh_internal_node(const LbvhArrays& a, int i) {
    const int d = lbvh_delta(a, i, int64_t(i) + 1) - lbvh_delta(a, i, int64_t(i) - 1) >= 0 ? 1 : -1;
    const int delta_min = lbvh_delta(a, i, int64_t(i) - d);
    int64_t l_max = 2;
    while (lbvh_delta(a, i, int64_t(i) + l_max * d) > delta_min) l_max *= 2;
    int64_t l = 0;
    for (int64_t t = l_max / 2; t >= 1; t /= 2)
        if (lbvh_delta(a, i, int64_t(i) + (l + t) * d) > delta_min) l += t;
    const int64_t j = int64_t(i) + l * d;
    const int delta_node = lbvh_delta(a, i, j);
    int64_t s = 0;
    for (int64_t div = 2;; div *= 2) {
        const int64_t t = (l + div - 1) / div;
        if (lbvh_delta(a, i, int64_t(i) + (s + t) * d) > delta_node) s += t;
        if (t <= 1) break;
    }
    const int gamma = int(int64_t(i) + s * d + (d < 0 ? -1 : 0));
    const int lo = int(i < j ? i : j), hi = int(i < j ? j : i);
    a.count[i] = hi - lo + 1;
    a.first[i] = lo;
    if (gamma == lo) {  // left child: the leaf gamma, or internal node gamma
        a.left[i] = ~gamma;
        a.leaf_parent[gamma] = i;
    } else {
        a.left[i] = gamma;
        a.parent[gamma] = i;
    }
    if (gamma + 1 == hi) {
        a.right[i] = ~(gamma + 1);
        a.leaf_parent[gamma + 1] = i;
    } else {
        a.right[i] = gamma + 1;
        a.parent[gamma + 1] = i;
    }
    if (i == 0) a.parent[0] = -1;
}

/// The LBVH's slots are the sorted positions.
SDF_CPU_GPU SDF_INLINE void lbvh_leaf_in_place(const LbvhArrays& a, int pos) {
    a.leaf_slot[pos] = pos;
    a.order[pos] = a.sorted[pos];
}

// --- Step 2': PLOC (Meister & Bittner 2018) ----------------------------------------------

/// The clusters of one PLOC iteration, in Morton order (host or device).
struct PlocArrays {
    int m = 0;                 ///< clusters this iteration
    int radius = 16;           ///< positions searched on each side
    int32_t* code = nullptr;   ///< child code of each cluster (lbvh_is_leaf)
    float* box = nullptr;      ///< 6 arrays of `stride` (ploc_box): min x y z, max x y z
    int32_t* count = nullptr;  ///< triangles in each cluster
    int32_t* nearest = nullptr;
    int32_t* merges = nullptr;  ///< 1 where the cluster merges with its (later) nearest neighbour
    int32_t* keeps = nullptr;   ///< 1 where the cluster survives the iteration (merged or not)
    int stride = 0;             ///< clusters each box array holds
};

/// Coordinate k of cluster i's box (0-2 min, 3-5 max). One array per coordinate, so the
/// threads of a warp, which take consecutive clusters, read consecutive words (in shared
/// memory a box of six words per cluster made each read six-way bank conflicted).
SDF_CPU_GPU SDF_INLINE float& ploc_box(const PlocArrays& p, int i, int k) { return p.box[size_t(k) * size_t(p.stride) + size_t(i)]; }

/// Cluster i of the first iteration: the leaf of sorted position i, its box rounded outward.
SDF_CPU_GPU SDF_INLINE void ploc_leaf_cluster(const LbvhArrays& a, const PlocArrays& p, int i) {
    const Int3 t = a.triangles[a.sorted[i]];
    const Vec3d v[3] = {a.vertices[t.x], a.vertices[t.y], a.vertices[t.z]};
    for (int x = 0; x < 3; ++x) {
        double lo = v[0][x], hi = v[0][x];
        for (int k = 1; k < 3; ++k) {
            lo = v[k][x] < lo ? v[k][x] : lo;
            hi = v[k][x] > hi ? v[k][x] : hi;
        }
        ploc_box(p, i, x) = float_below(lo);
        ploc_box(p, i, 3 + x) = float_above(hi);
    }
    p.code[i] = ~i;
    p.count[i] = 1;
}

/// Surface area (half of it: only the order matters) of the union of clusters i and j.
SDF_CPU_GPU SDF_INLINE float ploc_merged_area(const PlocArrays& p, int i, int j) {
    float e[3];
    for (int x = 0; x < 3; ++x) {
        const float lo = ploc_box(p, i, x) < ploc_box(p, j, x) ? ploc_box(p, i, x) : ploc_box(p, j, x);
        const float hi = ploc_box(p, i, 3 + x) > ploc_box(p, j, 3 + x) ? ploc_box(p, i, 3 + x) : ploc_box(p, j, 3 + x);
        e[x] = hi - lo;
    }
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

/// Cluster i's nearest neighbour within `radius` positions: the smallest merged area, ties
/// to the smaller pair (min, max) of positions. A total order on pairs, so the best pair of
/// the iteration is mutual and every iteration merges at least once.
SDF_CPU_GPU SDF_INLINE void ploc_nearest(const PlocArrays& p, int i) {
    const int lo = i - p.radius > 0 ? i - p.radius : 0;
    const int hi = i + p.radius < p.m - 1 ? i + p.radius : p.m - 1;
    int best = -1;
    float best_area = 0;
    for (int j = lo; j <= hi; ++j) {
        if (j == i) continue;
        const float area = ploc_merged_area(p, i, j);
        // For a fixed i, the pair (min(i,j), max(i,j)) orders as j does.
        if (best < 0 || area < best_area || (area == best_area && j < best)) {
            best = j;
            best_area = area;
        }
    }
    p.nearest[i] = best;
}

/// Whether cluster i starts a merge (mutual nearest neighbours, i the first), and whether it
/// survives the iteration (it is not the second of a merge).
SDF_CPU_GPU SDF_INLINE void ploc_flags_of(const PlocArrays& p, int i, int& merges, int& keeps) {
    const int j = p.nearest[i];
    const bool mutual = j >= 0 && p.nearest[j] == i;
    merges = mutual && i < j ? 1 : 0;
    keeps = mutual && i > j ? 0 : 1;
}
SDF_CPU_GPU SDF_INLINE void ploc_flags(const PlocArrays& p, int i) { ploc_flags_of(p, i, p.merges[i], p.keeps[i]); }

/// One cluster's entries in PlocArrays.
struct PlocCluster {
    float box[6];
    int32_t code;
    int32_t count;
};

SDF_CPU_GPU SDF_INLINE PlocCluster ploc_cluster(const PlocArrays& p, int i) {
    PlocCluster c;
    for (int k = 0; k < 6; ++k) c.box[k] = ploc_box(p, i, k);
    c.code = p.code[i];
    c.count = p.count[i];
    return c;
}

SDF_CPU_GPU SDF_INLINE void ploc_store(const PlocArrays& p, int i, const PlocCluster& c) {
    for (int k = 0; k < 6; ++k) ploc_box(p, i, k) = c.box[k];
    p.code[i] = c.code;
    p.count[i] = c.count;
}

/// Merges cluster i with its nearest neighbour into internal node `id` (ids count down from
/// n - 2, so the last merge, the root, is node 0): writes the node, returns the merged
/// cluster (the caller stores it where the next iteration finds it).
SDF_CPU_GPU SDF_INLINE PlocCluster ploc_merged(const LbvhArrays& a, const PlocArrays& p, int i, int id) {
    const int j = p.nearest[i];
    const int32_t l = p.code[i], r = p.code[j];
    a.left[id] = l;
    a.right[id] = r;
    if (lbvh_is_leaf(l)) a.leaf_parent[~l] = id;
    else a.parent[l] = id;
    if (lbvh_is_leaf(r)) a.leaf_parent[~r] = id;
    else a.parent[r] = id;
    PlocCluster c;
    c.count = p.count[i] + p.count[j];
    a.count[id] = c.count;
    for (int x = 0; x < 3; ++x) {
        c.box[x] = ploc_box(p, i, x) < ploc_box(p, j, x) ? ploc_box(p, i, x) : ploc_box(p, j, x);
        c.box[3 + x] = ploc_box(p, i, 3 + x) > ploc_box(p, j, 3 + x) ? ploc_box(p, i, 3 + x) : ploc_box(p, j, 3 + x);
    }
    c.code = id;
    return c;
}

/// Surviving cluster i of `from` (merged into node `id` where it starts a merge) stored at
/// position `to` of the next iteration's arrays `next`: other arrays than `from`'s, since a
/// merge reads its neighbour there (the device's tail compacts in place instead, with a
/// barrier between its reads and writes).
SDF_CPU_GPU SDF_INLINE void ploc_merge_compact(const LbvhArrays& a, const PlocArrays& from, const PlocArrays& next, int i,
                                               bool merges, int id, int to) {
    ploc_store(next, to, merges ? ploc_merged(a, from, i, id) : ploc_cluster(from, i));
}

SDF_CPU_GPU SDF_INLINE int lbvh_code_count(const LbvhArrays& a, int32_t code) { return lbvh_is_leaf(code) ? 1 : a.count[code]; }

/// The slot of the leaf at sorted position `pos`: the triangles left of it in the tree
/// (the counts of the left siblings on its path to the root).
SDF_CPU_GPU SDF_INLINE void ploc_leaf_slot(const LbvhArrays& a, int pos) {
    int slot = 0;
    int32_t code = ~pos;
    for (int node = a.leaf_parent[pos]; node >= 0; code = node, node = a.parent[node])
        if (a.right[node] == code) slot += lbvh_code_count(a, a.left[node]);
    a.leaf_slot[pos] = slot;
    a.order[slot] = a.sorted[pos];
}

/// Internal node i's first slot: its leftmost leaf's (after ploc_leaf_slot).
SDF_CPU_GPU SDF_INLINE void ploc_first_slot(const LbvhArrays& a, int i) {
    int32_t code = a.left[i];
    while (!lbvh_is_leaf(code)) code = a.left[code];
    a.first[i] = a.leaf_slot[~code];
}

// --- Both: the flat layout ------------------------------------------------------------------

SDF_CPU_GPU SDF_INLINE int32_t lbvh_child(const LbvhArrays& a, int i, int c) { return c == 0 ? a.left[i] : a.right[i]; }

/// Triangles under child c of internal node i, and its first slot.
SDF_CPU_GPU SDF_INLINE int lbvh_child_count(const LbvhArrays& a, int i, int c) { return lbvh_code_count(a, lbvh_child(a, i, c)); }
SDF_CPU_GPU SDF_INLINE int lbvh_child_first(const LbvhArrays& a, int i, int c) {
    const int32_t code = lbvh_child(a, i, c);
    return lbvh_is_leaf(code) ? a.leaf_slot[~code] : a.first[code];
}

/// Kept internal nodes become nodes of the flat layout; the others are inside leaves.
SDF_CPU_GPU SDF_INLINE bool lbvh_kept(const LbvhArrays& a, int i) { return a.count[i] > a.max_leaf; }

/// The sort key that puts kept nodes in depth-first pre-order (as the SAH builder numbers
/// them: a parent before its children, the left subtree before the right, so a traversal
/// walks nearby memory): by first slot, then larger count first (a node and its left
/// descendants share the first slot; each has fewer triangles than its parent). Unique
/// among kept nodes; the others sort last.
SDF_CPU_GPU SDF_INLINE uint64_t lbvh_preorder_key(const LbvhArrays& a, int i) {
    if (!lbvh_kept(a, i)) return ~uint64_t(0);
    return uint64_t(uint32_t(a.first[i])) << 32 | uint32_t(a.n - a.count[i]);
}

/// Which child of its parent the internal node i is.
SDF_CPU_GPU SDF_INLINE int lbvh_side(const LbvhArrays& a, int i) { return a.left[a.parent[i]] == i ? 0 : 1; }

/// Writes the child references of kept internal node i into its flat node (boxes follow).
SDF_CPU_GPU SDF_INLINE void lbvh_link_node(const LbvhArrays& a, int i) {
    BvhNode& node = a.nodes[a.kept_index[i]];
    for (int c = 0; c < 2; ++c) {
        const int count = lbvh_child_count(a, i, c);
        const bool leaf = count <= a.max_leaf;
        node.ref[c] = leaf ? lbvh_child_first(a, i, c) : a.kept_index[lbvh_child(a, i, c)];
        node.count[c] = leaf ? count : 0;
    }
}

// --- Step 3: boxes and moments, bottom-up -----------------------------------------------

/// What a child passes to its parent: its moments (radius filled later for inner children)
/// and sum a_i c_i, from which the parent's centre is formed.
struct LbvhSummary {
    float lo[3], hi[3];
    WindingMoments<double> m;
    Vec3d weighted{};
};

SDF_CPU_GPU SDF_INLINE Vec3d lbvh_corner(const LbvhArrays& a, int slot, int k) {
    const Int3 t = a.triangles[a.order[slot]];
    return a.vertices[k == 0 ? t.x : (k == 1 ? t.y : t.z)];
}

/// A leaf's box and moments from its triangles, by the formulas of core/winding/winding_bvh.cpp.
SDF_CPU_GPU SDF_INLINE LbvhSummary lbvh_leaf_summary(const LbvhArrays& a, int first, int count) {
    LbvhSummary s;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    WindingMoments<double>& m = s.m;
    for (int slot = first; slot < first + count; ++slot) {
        const Vec3d v[3] = {lbvh_corner(a, slot, 0), lbvh_corner(a, slot, 1), lbvh_corner(a, slot, 2)};
        for (int k = 0; k < 3; ++k)
            for (int x = 0; x < 3; ++x) {
                lo[x] = v[k][x] < lo[x] ? v[k][x] : lo[x];
                hi[x] = v[k][x] > hi[x] ? v[k][x] : hi[x];
            }
        const Vec3d area_normal = cross(v[1] - v[0], v[2] - v[0]) * 0.5;  // a_i n_i
        const double area = length(area_normal);
        m.area += area;
        m.normal_sum += area_normal;
        s.weighted += (v[0] + v[1] + v[2]) * (area / 3.0);
    }
    for (int x = 0; x < 3; ++x) { s.lo[x] = float_below(lo[x]); s.hi[x] = float_above(hi[x]); }
    m.center = m.area > 0 ? s.weighted / m.area : lbvh_corner(a, first, 0);
    for (int slot = first; slot < first + count; ++slot) {
        const Vec3d v[3] = {lbvh_corner(a, slot, 0), lbvh_corner(a, slot, 1), lbvh_corner(a, slot, 2)};
        for (int k = 0; k < 3; ++k) {
            const double r = length(v[k] - m.center);
            m.radius = m.radius < r ? r : m.radius;
        }
        const Vec3d area_normal = cross(v[1] - v[0], v[2] - v[0]) * 0.5;
        const Vec3d h = (v[0] + v[1] + v[2]) / 3.0 - m.center;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) m.second[3 * i + j] += h[i] * area_normal[j];
    }
    m.radius *= 1.0 + 1e-12;  // as winding_bvh.cpp: rounding of |v - p~| must not shrink the ball
    return s;
}

/// Stores s as child c of flat node `node`.
SDF_CPU_GPU SDF_INLINE void lbvh_store(const LbvhArrays& a, int node, int c, const LbvhSummary& s) {
    BvhNode& n = a.nodes[node];
    n.min_x[c] = s.lo[0]; n.min_y[c] = s.lo[1]; n.min_z[c] = s.lo[2];
    n.max_x[c] = s.hi[0]; n.max_y[c] = s.hi[1]; n.max_z[c] = s.hi[2];
    a.moments[node].child[c] = s.m;
    a.weighted[2 * node + c] = s.weighted;
}

/// Loads child c of flat node `node` as another element stored it.
SDF_CPU_GPU SDF_INLINE LbvhSummary lbvh_load_child(const LbvhArrays& a, int node, int c) {
    LbvhSummary s;
    const BvhNode& n = a.nodes[node];
    s.lo[0] = lbvh_load(&n.min_x[c]); s.lo[1] = lbvh_load(&n.min_y[c]); s.lo[2] = lbvh_load(&n.min_z[c]);
    s.hi[0] = lbvh_load(&n.max_x[c]); s.hi[1] = lbvh_load(&n.max_y[c]); s.hi[2] = lbvh_load(&n.max_z[c]);
    const WindingMoments<double>& m = a.moments[node].child[c];
    s.m.center = {lbvh_load(&m.center.x), lbvh_load(&m.center.y), lbvh_load(&m.center.z)};
    s.m.radius = lbvh_load(&m.radius);
    s.m.area = lbvh_load(&m.area);
    s.m.normal_sum = {lbvh_load(&m.normal_sum.x), lbvh_load(&m.normal_sum.y), lbvh_load(&m.normal_sum.z)};
    for (int k = 0; k < 9; ++k) s.m.second[k] = lbvh_load(&m.second[k]);
    const Vec3d& w = a.weighted[2 * node + c];
    s.weighted = {lbvh_load(&w.x), lbvh_load(&w.y), lbvh_load(&w.z)};
    return s;
}

/// The union of two children: box, area, N, sum a_i c_i, centre, and M moved to the new
/// centre (M = sum_k M_k + (p~_k - p~) N_k^T). The radius is set by the radius pass.
SDF_CPU_GPU SDF_INLINE LbvhSummary lbvh_merge(const LbvhSummary& l, const LbvhSummary& r) {
    LbvhSummary s;
    for (int x = 0; x < 3; ++x) {
        s.lo[x] = l.lo[x] < r.lo[x] ? l.lo[x] : r.lo[x];
        s.hi[x] = l.hi[x] > r.hi[x] ? l.hi[x] : r.hi[x];
    }
    s.m.area = l.m.area + r.m.area;
    s.m.normal_sum = l.m.normal_sum + r.m.normal_sum;
    s.weighted = l.weighted + r.weighted;
    s.m.center = s.m.area > 0 ? s.weighted / s.m.area : l.m.center;
    const Vec3d dl = l.m.center - s.m.center, dr = r.m.center - s.m.center;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            s.m.second[3 * i + j] = (l.m.second[3 * i + j] + dl[i] * l.m.normal_sum[j]) +
                                    (r.m.second[3 * i + j] + dr[i] * r.m.normal_sum[j]);
    s.m.radius = 0;
    return s;
}

/// Kept internal node i: stores its leaf children, then carries complete nodes upward; the
/// second of two children to arrive at a node merges them (one pass, no ordering needed).
SDF_CPU_GPU SDF_INLINE void lbvh_refit_from(const LbvhArrays& a, int i) {
    int leaves = 0;
    for (int c = 0; c < 2; ++c) {
        const int count = lbvh_child_count(a, i, c);
        if (count > a.max_leaf) continue;
        lbvh_store(a, a.kept_index[i], c, lbvh_leaf_summary(a, lbvh_child_first(a, i, c), count));
        ++leaves;
    }
    if (leaves == 0) return;  // both children are internal: they arrive here
    if (leaves == 1) {
        lbvh_fence();
        if (lbvh_atomic_add(&a.arrivals[i], 1u) == 0) return;  // the internal child is still on its way
    }
    for (int node = i; node != 0;) {
        const int index = a.kept_index[node];
        const LbvhSummary s = lbvh_merge(lbvh_load_child(a, index, 0), lbvh_load_child(a, index, 1));
        const int p = a.parent[node];
        lbvh_store(a, a.kept_index[p], lbvh_side(a, node), s);
        lbvh_fence();
        if (lbvh_atomic_add(&a.arrivals[p], 1u) == 0) return;
        node = p;
    }
}

/// Kept internal node i (after the refit): raises the radius of every ancestor child that
/// holds one of i's leaves to that leaf's farthest vertex (times 1 + 1e-12, as a leaf's);
/// returns i's depth (the root's is 1, as the SAH builder counts).
SDF_CPU_GPU SDF_INLINE int lbvh_radius_from(const LbvhArrays& a, int i) {
    int depth = 1;
    for (int node = i; node != 0; node = a.parent[node]) ++depth;
    for (int c = 0; c < 2; ++c) {
        const int count = lbvh_child_count(a, i, c);
        if (count > a.max_leaf) continue;
        const int first = lbvh_child_first(a, i, c);
        for (int node = i; node != 0; node = a.parent[node]) {
            const int p = a.parent[node];
            WindingMoments<double>& m = a.moments[a.kept_index[p]].child[lbvh_side(a, node)];
            const Vec3d centre = m.center;
            // The largest squared distance, then one root: the square root is monotone and
            // correctly rounded, so this is the largest length() to the bit.
            double r2 = 0;
            for (int slot = first; slot < first + count; ++slot)
                for (int k = 0; k < 3; ++k) {
                    const double d2 = length_squared(lbvh_corner(a, slot, k) - centre);
                    r2 = r2 < d2 ? d2 : r2;
                }
            lbvh_atomic_max(&m.radius, std::sqrt(r2) * (1.0 + 1e-12));
        }
    }
    return depth;
}

}  // namespace sdf
