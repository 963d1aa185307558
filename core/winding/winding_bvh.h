/// @file winding_bvh.h
/// @brief The moments of the fast winding number (kernels/winding/fast_winding_number.h),
/// computed once per mesh over the nodes of its TriangleBvh, and the views that the host
/// and a device upload give to the kernel.
#pragma once

#include <memory>
#include <vector>

#include "core/bvh/triangle_bvh.h"
#include "core/mesh/prepared_mesh.h"
#include "kernels/winding/fast_winding_number.h"

namespace sdf {

class WindingBvh {
public:
    std::shared_ptr<const TriangleBvh> bvh;
    std::vector<WindingNode<double>> moments;  ///< one per bvh->nodes entry
    std::vector<WindingNode<float>> moments_float;
    double seconds = 0;                        ///< time to compute the moments

    /// The view over `mesh` (the mesh the BVH was built from), in precision T.
    template <typename T>
    WindingView<T> view(const PreparedMesh& mesh) const;
};

/// Moments of every node child of `bvh` (built from `mesh`): center, radius, area, the
/// area-weighted normal sum and the second-order matrix. O(triangles x depth), on `threads`
/// threads (0: all hardware threads; the moments do not depend on it).
WindingBvh build_winding_bvh(const PreparedMesh& mesh, std::shared_ptr<const TriangleBvh> bvh, int threads = 0);

/// Over the mesh's own BVH (PreparedMesh::bvh()).
WindingBvh build_winding_bvh(const PreparedMesh& mesh);

/// The mesh's largest |coordinate| (WindingView::scale: the certified bounds' X).
double winding_scale(const PreparedMesh& mesh);

}  // namespace sdf
