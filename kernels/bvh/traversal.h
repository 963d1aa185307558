/// @file traversal.h
/// @brief The nearest-first walk of a BVH (bvh_node.h), written once for every search, host
/// and device.
///
/// Ordered depth-first traversal with a shrinking bound (Aila & Laine, "Understanding the
/// Efficiency of Ray Traversal on GPUs", HPG 2009, on their two-box node): the nearer child is
/// entered first, the farther one waits on the stack with its key and is dropped when popped
/// if the bound has shrunk past it. The loop, the stack and the order exist here only; a query
/// is a policy that measures a node's children, scans leaves and says which entries stay open,
/// as cuBQL's one traversal takes the query as a lambda. Its queries: the nearest triangle of
/// one point, of a packet of points and of a warp's points (closest_triangle_bvh.h,
/// closest_triangles_packet.h, cuda/bvh/bvh_warp_kernel.cuh), a brick's candidate leaves
/// (cuda/bvh/bvh_candidates_kernel.cuh) and the closest ray hit (ray_traversal.h).
///
/// The winding numbers' walks (kernels/winding/) open every child their far-field test
/// rejects, in child order, and keep their own loops: written as one depth-first walk with the
/// query as a lambda they ran 9-17% slower on the CPU (docs/bvh.md, "One traversal").
#pragma once

#include <cstdint>

#include "kernels/bvh/bvh_node.h"

namespace sdf {

/// A node's two children as a nearest-first query measured them: child `nearer` is entered
/// first; a key is what a child waits with on the stack (a squared distance, a ray's entry).
/// A packet or a warp votes on both children on entry (`*_wanted`); a one-point query leaves
/// them true and is asked when each child's turn comes. Two named fields rather than arrays
/// indexed by `nearer`: a GPU keeps dynamically indexed arrays in local memory.
template <typename Key>
struct ChildOrder {
    int nearer = 0;
    Key near_key{}, far_key{};
    bool near_wanted = true, far_wanted = true;

    /// Children 0 and 1's keys and votes put in the order `nearer` says.
    SDF_CPU_GPU SDF_INLINE static ChildOrder ordered(int nearer, const Key& key0, const Key& key1,
                                                     bool want0 = true, bool want1 = true) {
        ChildOrder c;
        c.nearer = nearer;
        c.near_key = nearer ? key1 : key0;
        c.far_key = nearer ? key0 : key1;
        c.near_wanted = nearer ? want1 : want0;
        c.far_wanted = nearer ? want0 : want1;
        return c;
    }
};

/// For walks whose stacked entries need no key (they are entered whatever happened since).
struct NoKey {};

/// The walk's stack entries in the thread's own memory, two arrays the caller declares (the
/// walk keeps the depth, `top`, in a register). Arrays, not a struct holding them: ptxas
/// then fits the certify kernel's three walks in 1,776 bytes of stack rather than 2,032.
template <typename Key>
struct LocalStack {
    int32_t* node;
    Key* key;
    SDF_CPU_GPU SDF_INLINE void store(int top, int32_t n, const Key& k) {
        node[top] = n;
        key[top] = k;
    }
    SDF_CPU_GPU SDF_INLINE Key key_at(int top) const { return key[top]; }
    SDF_CPU_GPU SDF_INLINE int32_t node_at(int top) const { return node[top]; }
    SDF_CPU_GPU SDF_INLINE void begin_pops() {}
    SDF_CPU_GPU SDF_INLINE void end_pops() {}
};

/// Nearest-first walk from the root. The query `q` provides
///   ChildOrder<Key> measure(const BvhNode& n)   both children's keys and the nearer child;
///   bool enter(const Key& key)                  whether a wanted child may still hold what is
///       sought: asked for the nearer child, then (after its leaf, if it is one, was scanned
///       and the bound shrank) for the farther;
///   void leaf(int32_t first, int32_t count)     scans a leaf's slots, shrinking the bound;
///   void node_done()                            after both children (a warp agrees on its bound);
///   bool still_open(const Key& key)             whether a stacked entry is still worth entering.
/// An inner child to be entered is walked next without a stack round trip; when both are,
/// the farther is pushed.
template <typename Key, typename Query, typename Stack>
SDF_CPU_GPU SDF_INLINE void nearest_first_walk(const BvhNode* nodes, Query& q, Stack& stack) {
    int top = 0;
    int32_t node = 0;
    while (node >= 0) {
        const BvhNode n = nodes[node];
        const ChildOrder<Key> c = q.measure(n);
        // The children's refs by selects: indexing the node by `nearer` kept a copy of it in
        // local memory on the GPU (64 bytes stored and read back at every node).
        const bool second_first = c.nearer != 0;
        const int32_t near_ref = second_first ? n.ref[1] : n.ref[0], far_ref = second_first ? n.ref[0] : n.ref[1];
        const int32_t near_count = second_first ? n.count[1] : n.count[0];
        const int32_t far_count = second_first ? n.count[0] : n.count[1];
        int32_t next = -1;
        if (c.near_wanted && q.enter(c.near_key)) {
            if (bvh_child_is_leaf(near_ref, near_count)) q.leaf(near_ref, near_count);
            else next = near_ref;
        }
        if (c.far_wanted && q.enter(c.far_key)) {
            if (bvh_child_is_leaf(far_ref, far_count)) q.leaf(far_ref, far_count);
            else if (next < 0) next = far_ref;
            else {
                SDF_DCHECK(top < kBvhMaxDepth);
                stack.store(top++, far_ref, c.far_key);
            }
        }
        q.node_done();
        stack.begin_pops();
        while (next < 0 && top > 0) {  // a closed entry's node is never read
            --top;
            if (q.still_open(stack.key_at(top))) next = stack.node_at(top);
        }
        stack.end_pops();
        node = next;
    }
}

template <typename Key, typename Query>
SDF_CPU_GPU SDF_INLINE void nearest_first_walk(const BvhNode* nodes, Query& q) {
    int32_t node[kBvhMaxDepth];
    Key key[kBvhMaxDepth];
    LocalStack<Key> stack{node, key};
    nearest_first_walk<Key>(nodes, q, stack);
}

}  // namespace sdf
