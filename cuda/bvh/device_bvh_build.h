/// @file device_bvh_build.h
/// @brief The BVH built on the GPU by the steps of kernels/bvh/lbvh_steps.h: Morton keys,
/// CUB radix sort, the tree (PLOC by default, or the LBVH radix tree), leaves of <= 4
/// triangles, nodes in pre-order, one bottom-up pass for the float boxes and the winding
/// moments, one for the exact radii; the packed search constants gathered into BVH order,
/// and the slot of every triangle for the certified search. Bit for bit the tree of
/// core/bvh/lbvh.h (its host emulation), which the CPU tests check.
#pragma once

#include <memory>
#include <string>

#include "core/bvh/lbvh.h"
#include "core/mesh/prepared_mesh.h"
#include "cuda/util/device_buffer.h"

namespace sdf::cuda {

struct DeviceLbvh {
    DeviceBuffer<BvhNode> nodes;
    DeviceBuffer<WindingNode<double>> moments;   ///< one per node (fast winding number)
    DeviceBuffer<int32_t> triangle_index;        ///< BVH slot -> prepared-mesh triangle
    DeviceBuffer<int32_t> slot_of;               ///< prepared-mesh triangle -> BVH slot
    DeviceBuffer<PackedTriangle<float>> packed_float;    ///< search constants in BVH order
    DeviceBuffer<PackedTriangle<double>> packed_double;
    BvhBuildStats stats;       ///< seconds: wall time of the whole build (the host's search bound included)
    double device_seconds = 0;  ///< CUDA events around the same work
    bool within_depth = true;   ///< false: deeper than kBvhMaxDepth, not to be queried
    FloatSearchBound bound;     ///< the search bound of these triangles (search_certificate.h): the
                                ///< certified float search's, and the double view's pruning margin
    int num_nodes = 0, num_triangles = 0;

    template <typename T>
    BvhView<T> view() const;

    /// The build copied back (nodes, slots, packed constants, moments, stats), for the tests.
    LbvhBuild download() const;
};

/// Builds on the current device from the prepared mesh and its device vertices and
/// triangles (`vertices`, `triangles`: a DeviceMesh<double>'s). Null when the mesh fits one
/// leaf (no tree to build; the host build handles it). Throws on CUDA errors.
/// The packed search constants of the triangle in each slot of `order` (slot -> triangle,
/// `n` slots), made on the device from the double mesh (`vertices`, `triangles`: a
/// DeviceMesh<double>'s) with the bits of the host's mesh buffers, and every triangle's
/// slot; `packed_float` and `slot_of` may be null. For a tree built on the host, whose
/// constants would otherwise be uploaded (29 MB at 100k triangles). Asynchronous (stream 0).
void pack_in_slot_order(const Vec3d* vertices, const Int3* triangles, const int32_t* order, int n,
                        PackedTriangle<float>* packed_float, PackedTriangle<double>* packed_double, int32_t* slot_of);

std::unique_ptr<DeviceLbvh> build_lbvh_on_device(const PreparedMesh& mesh, const Vec3d* vertices, const Int3* triangles,
                                                 const GpuBvhBuildOptions& options = {});

}  // namespace sdf::cuda
