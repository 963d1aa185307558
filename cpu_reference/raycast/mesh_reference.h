/// @file mesh_reference.h
/// @brief The ground truth of the image metrics: the mesh itself ray-traced with the same
/// camera and shading as the reconstructions (kernels/raycast/shading.h).
///
/// Exact closest hits in double: the watertight ray-triangle test
/// (kernels/raycast/ray_triangle.h; no tolerance, no cracks along shared edges) over the
/// project's binned-SAH BVH (core/bvh/triangle_bvh.h) with the closest-hit
/// traversal of kernels/bvh/ray_traversal.h. The normal is the triangle's face normal; with
/// `interpolate_normals` (off by default) the barycentric blend of the angle-weighted vertex
/// normals. The depth is the hit distance along the unit ray direction, as for the ray
/// caster. The renderer is built once per mesh (the BVH) and renders any number of views.
#pragma once

#include <memory>

#include "core/bvh/triangle_bvh.h"
#include "core/mesh/prepared_mesh.h"
#include "core/raycast/rendered_image.h"
#include "core/raycast/views.h"

namespace sdf {

struct MeshRenderOptions {
    bool interpolate_normals = false;
    int threads = 0;  ///< 0 = all hardware threads
    bool progress = true;
    int tile = 16;
};

class MeshReferenceRenderer {
public:
    /// Keeps a reference to `mesh`, which must outlive the renderer.
    explicit MeshReferenceRenderer(const PreparedMesh& mesh);
    RenderedImage render(const CameraSpec& camera, const MeshRenderOptions& options = {}) const;
    /// The closest hit of one ray: record and, through *triangle, the prepared-mesh triangle.
    PixelRecord cast(const Ray<double>& ray, const Vec3d& key_light, bool interpolate_normals,
                     int* triangle = nullptr) const;

private:
    const PreparedMesh& mesh_;
    std::shared_ptr<const TriangleBvh> bvh_;  ///< the mesh's own (PreparedMesh::bvh())
    std::vector<Vec3d> corners_;  ///< 3 vertices per BVH slot, in BVH order
};

/// One view, over the mesh's BVH.
RenderedImage render_mesh_reference(const PreparedMesh& mesh, const CameraSpec& camera,
                                    const MeshRenderOptions& options = {});

}  // namespace sdf
