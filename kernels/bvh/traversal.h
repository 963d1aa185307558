/// @file traversal.h
/// @brief The two walks of a BVH (bvh_node.h), written once for every query, host and device.
///
/// The loop, the stack and the visiting order exist here only; a query is a policy that
/// measures a node's children, handles leaves and says which entries stay open, as in cuBQL,
/// where one traversal takes the query as a lambda.
///
///   nearest_first_walk(): ordered depth-first traversal with a shrinking bound (Aila & Laine,
///     "Understanding the Efficiency of Ray Traversal on GPUs", HPG 2009, on their two-box
///     node): the nearer child is entered first, the farther one waits on the stack with its
///     key and is dropped when popped if the bound has shrunk past it. The nearest triangle of
///     one point, of a packet of points and of a warp's points (closest_triangle_bvh.h,
///     closest_triangles_packet.h, cuda/bvh/bvh_warp_kernel.cuh), the closest ray hit
///     (ray_traversal.h) and a brick's candidate leaves (cuda/bvh/bvh_candidates_kernel.cuh).
///   depth_first_walk(): every wanted child, children 0 then 1 at each node, the last opened
///     walked first. Winding numbers add their terms in exactly this order, so a packet's or
///     a warp's lanes get the bits of their own walk (fast_winding_number.h,
///     certified_winding.h and their packet and warp forms) and a segment's crossings
///     (surface_side.h).
#pragma once

#include <cstdint>
#include <type_traits>

#include "kernels/bvh/bvh_node.h"

namespace sdf {

/// A node's two children as a nearest-first query measured them: child `nearer` is entered
/// first; key[c] is what child c waits with on the stack (a squared distance, a ray's entry).
template <typename Key>
struct ChildOrder {
    int nearer = 0;
    Key key[2];
};

/// For walks whose stacked entries need no key (they are entered whatever happened since).
struct NoKey {};

/// The walk's stack in the thread's own memory.
template <typename Key>
struct LocalStack {
    int32_t node[kBvhMaxDepth];
    Key key[kBvhMaxDepth];
    int top = 0;
    SDF_CPU_GPU SDF_INLINE void push(int32_t n, const Key& k) {
        SDF_DCHECK(top < kBvhMaxDepth);
        node[top] = n;
        key[top] = k;
        ++top;
    }
    SDF_CPU_GPU SDF_INLINE bool empty() const { return top == 0; }
    SDF_CPU_GPU SDF_INLINE int32_t pop(Key& k) {
        --top;
        k = key[top];
        return node[top];
    }
    SDF_CPU_GPU SDF_INLINE void begin_pops() {}
    SDF_CPU_GPU SDF_INLINE void end_pops() {}
};

/// Nearest-first walk from the root. The query `q` provides
///   ChildOrder<Key> measure(const BvhNode& n)   both children's keys and the nearer child;
///   bool enter(const ChildOrder<Key>& c, int child)   whether a child may still hold what
///       is sought: asked for the nearer child, then (after its leaf, if it is one, was
///       scanned and the bound shrank) for the farther;
///   void leaf(int32_t first, int32_t count)     scans a leaf's slots, shrinking the bound;
///   void node_done()                            after both children (a warp agrees on its bound);
///   bool still_open(const Key& key)             whether a stacked entry is still worth entering.
/// An inner child to be entered is walked next without a stack round trip; when both are,
/// the farther is pushed.
template <typename Key, typename Query, typename Stack>
SDF_CPU_GPU SDF_INLINE void nearest_first_walk(const BvhNode* nodes, Query& q, Stack& stack) {
    int32_t node = 0;
    while (node >= 0) {
        const BvhNode n = nodes[node];
        const ChildOrder<Key> c = q.measure(n);
        const int nearer = c.nearer, farther = 1 - nearer;
        int32_t next = -1;
        if (q.enter(c, nearer)) {
            if (bvh_child_is_leaf(n, nearer)) q.leaf(n.ref[nearer], n.count[nearer]);
            else next = n.ref[nearer];
        }
        if (q.enter(c, farther)) {
            if (bvh_child_is_leaf(n, farther)) q.leaf(n.ref[farther], n.count[farther]);
            else if (next < 0) next = n.ref[farther];
            else stack.push(n.ref[farther], c.key[farther]);
        }
        q.node_done();
        stack.begin_pops();
        while (next < 0 && !stack.empty()) {
            Key key;
            const int32_t entry = stack.pop(key);
            if (q.still_open(key)) next = entry;
        }
        stack.end_pops();
        node = next;
    }
}

template <typename Key, typename Query>
SDF_CPU_GPU SDF_INLINE void nearest_first_walk(const BvhNode* nodes, Query& q) {
    LocalStack<Key> stack;
    nearest_first_walk<Key>(nodes, q, stack);
}

/// Nothing travels with a depth-first entry (one point's walk).
struct NoPayload {};

/// The lanes of a K-point packet that opened a node (1: opened, 0: not): a packet's payload.
template <int K>
struct PacketLanes {
    int64_t lane[K];
};

/// Depth-first walk from the root with `root` as the root's payload. At each node taken from
/// the stack the query is asked for child 0, then child 1:
///   bool open(int32_t node, const BvhNode& n, int c, const Payload& in, Payload& out)
/// adds what it accepts of child c (a far-field term, a leaf's triangles) and returns true to
/// open inner child c with payload `out` (e.g. the lanes of a packet that opened it; `in` is
/// the payload the node was opened with). Opened children are pushed in that order, so child
/// 1's subtree is walked before child 0's.
template <typename Payload, typename Open>
SDF_CPU_GPU SDF_INLINE void depth_first_walk(const BvhNode* nodes, const Payload& root, Open&& open) {
    int32_t stack_node[kBvhMaxDepth + 1];
    Payload stack_payload[kBvhMaxDepth + 1];
    stack_node[0] = 0;
    stack_payload[0] = root;
    int top = 1;
    while (top > 0) {
        --top;
        const int32_t node = stack_node[top];
        const Payload in = stack_payload[top];  // a copy: pushing child 0 overwrites the slot
        const BvhNode& n = nodes[node];
        for (int c = 0; c < 2; ++c) {
            if (!open(node, n, c, in, stack_payload[top])) continue;
            SDF_DCHECK(top <= kBvhMaxDepth);
            stack_node[top] = n.ref[c];
            ++top;
        }
    }
}

}  // namespace sdf
