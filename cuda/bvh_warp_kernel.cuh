/// @file bvh_warp_kernel.cuh
/// @brief BVH search with one traversal per warp: the 32 threads of a warp (a compact 8 x 4 x
/// 4 brick of lattice points, 4 points per thread, as in bvh_kernel.cuh) walk the tree
/// together, so node loads are broadcasts and the warp never diverges in the traversal.
///
/// The same exactness argument as closest_triangles_packet.h, over 128 points instead of 4:
/// a child is entered when its box is nearer to at least one point than that point's best
/// squared distance (a warp vote), and a subtree on the stack is dropped only when its
/// nearest point is no nearer than the largest best of the warp. Every point therefore gets
/// its own exact minimum (up to ties). Leaves are scanned by every thread for its 4 points.
#pragma once

#include "kernels/bvh/closest_triangles_packet.h"
#include "cuda/bvh_kernel.cuh"

namespace sdf::cuda {

constexpr unsigned kFullWarp = 0xffffffffu;

template <typename T>
__device__ SDF_INLINE T warp_min(T v) {
    for (int o = 16; o > 0; o >>= 1) v = min(v, __shfl_xor_sync(kFullWarp, v, o));
    return v;
}

template <typename T>
__device__ SDF_INLINE T warp_max(T v) {
    for (int o = 16; o > 0; o >>= 1) v = max(v, __shfl_xor_sync(kFullWarp, v, o));
    return v;
}

/// Where a warp's points come from: thread t owns `count` consecutive piece-local ids from
/// `first` (count 0: none). A lattice slab gives every warp an 8 x 4 x 4 brick (SlabGeometry);
/// a point list sorted into Morton order gives it 128 consecutive points, which are then
/// neighbours in space as well (kernels/core/morton.h).
struct SlabLayout {
    GridRangePiece piece;
    SlabGeometry slab;
    SDF_CPU_GPU int64_t threads() const { return slab.threads(); }
    SDF_CPU_GPU int points_of(int64_t t, int64_t& first) const {
        first = 0;
        if (t >= slab.threads()) return 0;
        const Int3 s = slab.run_start(t);
        if (s.x >= slab.resolution.x || s.y >= slab.resolution.y || s.z >= slab.nz) return 0;
        first = s.x + int64_t(slab.resolution.x) * (s.y + int64_t(slab.resolution.y) * s.z);
        return min(kRunPoints, slab.resolution.x - s.x);
    }
    SDF_CPU_GPU Vec3d position(int64_t i) const { return piece.position(i); }
};

struct ListLayout {
    PointListPiece piece;
    SDF_CPU_GPU int64_t threads() const { return (piece.size() + kRunPoints - 1) / kRunPoints; }
    SDF_CPU_GPU int points_of(int64_t t, int64_t& first) const {
        first = t * kRunPoints;
        const int64_t left = piece.size() - first;
        if (left <= 0) first = 0;
        return left <= 0 ? 0 : int(left < kRunPoints ? left : kRunPoints);
    }
    SDF_CPU_GPU Vec3d position(int64_t i) const { return piece.position(i); }
};

/// Loads thread t's points into a packet; lanes without points get best = -1, so they never
/// want a box or a triangle and never hold the warp back.
template <typename T, typename Layout>
__device__ SDF_INLINE int load_packet(const Layout& layout, int64_t t, int64_t& first, BvhPacket<T, kRunPoints>& pk) {
    const int count = layout.points_of(t, first);
    for (int k = 0; k < kRunPoints; ++k) {
        const Vec3<T> p(layout.position(first + (k < count ? k : 0)));
        pk.x[k] = p.x; pk.y[k] = p.y; pk.z[k] = p.z;
        pk.best_q[k] = count > 0 ? T(INFINITY) : T(-1);
        pk.best_slot[k] = -1;
        pk.best_triangle[k] = -1;
    }
    return count;
}

template <typename T, typename Layout>
__global__ void __launch_bounds__(kBvhThreads) nearest_triangle_bvh_warp(BvhView<T> bvh, Layout layout, int* nearest) {
    constexpr int kWarps = kBvhThreads / 32;
    __shared__ int32_t stack_node[kWarps][kBvhMaxDepth];
    __shared__ T stack_d2[kWarps][kBvhMaxDepth];
    const int w = threadIdx.x / 32;

    // Every thread stays to the end: the votes and shuffles need the whole warp.
    const int64_t t = int64_t(blockIdx.x) * blockDim.x + threadIdx.x;
    int64_t first = 0;
    BvhPacket<T, kRunPoints> pk;
    const int count = load_packet<T>(layout, t, first, pk);
    const bool valid = count > 0;

    T worst = warp_max(valid ? T(INFINITY) : T(-1));
    int top = 0;  // warp-uniform
    int32_t node = 0;
    while (node >= 0) {
        const BvhNode n = bvh.nodes[node];  // one address for the whole warp
        T d0, d1;
        const bool w0 = detail::child_wanted(n, 0, pk, d0), w1 = detail::child_wanted(n, 1, pk, d1);
        const bool want0 = __any_sync(kFullWarp, w0), want1 = __any_sync(kFullWarp, w1);
        const T m0 = warp_min(valid ? d0 : T(INFINITY)), m1 = warp_min(valid ? d1 : T(INFINITY));
        const int near = m1 < m0 ? 1 : 0;
        const bool want_near = near ? want1 : want0, want_far = near ? want0 : want1;
        int32_t next = -1;
        bool scanned = false;
        if (want_near) {
            if (bvh_child_is_leaf(n, near)) {
                detail::scan_leaf_packet(bvh, n.ref[near], n.count[near], pk);
                scanned = true;
            } else {
                next = n.ref[near];
            }
        }
        if (want_far) {
            const int far = 1 - near;
            if (bvh_child_is_leaf(n, far)) {
                detail::scan_leaf_packet(bvh, n.ref[far], n.count[far], pk);
                scanned = true;
            } else if (next < 0) {
                next = n.ref[far];
            } else {
                if (threadIdx.x % 32 == 0) {
                    stack_node[w][top] = n.ref[far];
                    stack_d2[w][top] = near ? m0 : m1;  // the nearest point's distance: a bound for all
                }
                ++top;
            }
        }
        if (scanned) {
            T mine = pk.best_q[0];
            for (int k = 1; k < kRunPoints; ++k) mine = max(mine, pk.best_q[k]);
            worst = warp_max(mine);
        }
        __syncwarp();
        while (next < 0 && top > 0) {
            --top;
            if (may_hold_nearer(stack_d2[w][top], worst)) next = stack_node[w][top];
        }
        __syncwarp();
        node = next;
    }
    for (int k = 0; k < count; ++k) nearest[first + k] = bvh.triangle_index[pk.best_slot[k]];
}

}  // namespace sdf::cuda
