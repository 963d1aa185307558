/// @file lbvh.h
/// @brief The BVH of the GPU build (LBVH or PLOC), emulated on the host: the same
/// per-element steps (kernels/bvh/lbvh_steps.h) run one after another, so this produces
/// the tree, boxes and winding moments of cuda/bvh/device_bvh_build.h bit for bit. The tests
/// check the tree and its queries here on the CPU; the GPU test compares the two builds.
#pragma once

#include <vector>

#include "core/bounds3.h"
#include "core/bvh/triangle_bvh.h"
#include "kernels/winding/winding_moments.h"

namespace sdf {

/// The cube the Morton keys quantise: the box's min corner and 1 / its largest extent.
struct LbvhKeyFrame {
    Vec3d lo{};
    double inv_extent = 1;
};
LbvhKeyFrame lbvh_key_frame(const Bounds3& mesh_box);

struct LbvhBuild {
    TriangleBvh bvh;                           ///< nodes, slot -> triangle, packed in BVH order, stats
    std::vector<WindingNode<double>> moments;  ///< one per node (fast winding number)
    /// False when the tree is deeper than kBvhMaxDepth: then `bvh` must not be queried (the
    /// sampler falls back to the SAH build and says so).
    bool within_depth = true;
};

/// Which tree the GPU build makes over the Morton-sorted triangles (kernels/bvh/lbvh_steps.h).
enum class GpuBvhBuilder { Lbvh, Ploc };

struct GpuBvhBuildOptions {
    GpuBvhBuilder builder = GpuBvhBuilder::Ploc;
    int max_leaf = 4;         ///< leaves hold at most this many triangles
    int ploc_radius = 16;     ///< PLOC's search radius (positions on each side)
    /// Device only: once at most this many clusters are left, one block runs PLOC's
    /// remaining iterations in shared memory (0: a launch sequence per iteration to the
    /// end); more than the block holds (6144 clusters, or fewer where the device's shared
    /// memory per block is smaller: cuda/bvh/device_bvh_build.cu) start where it can. The
    /// tree is the same.
    int ploc_tail_clusters = 4096;
    /// Host emulation only: 0 runs every step's elements in order; otherwise in an order
    /// shuffled by this seed, as a GPU may schedule them (the result must not change).
    uint64_t emulation_shuffle_seed = 0;
};

const char* gpu_bvh_builder_name(GpuBvhBuilder b);

/// Builds the tree of the triangles (more than `max_leaf` of them). `mesh_box` must contain
/// every vertex (a PreparedMesh's bounds()).
LbvhBuild build_lbvh(const BvhBuildInput& input, const Bounds3& mesh_box, const GpuBvhBuildOptions& options = {});

template <class Mesh>
LbvhBuild build_lbvh(const Mesh& mesh, const GpuBvhBuildOptions& options = {}) {
    return build_lbvh(BvhBuildInput{mesh.vertices(), mesh.triangles(), mesh.template buffers<float>().packed,
                                    mesh.template buffers<double>().packed, mesh.name(), &mesh.search_bound()},
                      mesh.bounds(), options);
}

}  // namespace sdf
