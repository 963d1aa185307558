/// @file surface_sides.h
/// @brief The table of kernels/winding/surface_side.h for one mesh: the winding number in
/// front of every triangle of a closed mesh that no intersection meets, one certified
/// evaluation per edge-connected component of such triangles. Built once, when a sampler with
/// the certified winding sign is bound to the mesh (core/sampling/sampler_sign.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "kernels/winding/surface_side.h"

namespace sdf {

struct SurfaceSides {
    /// Per prepared triangle: the winding number in front of it, or kSurfaceSideUnknown;
    /// empty when the mesh is not closed and consistently oriented with its intersections
    /// checked (then every point takes the ladder).
    std::vector<int8_t> front_winding;
    /// Per prepared triangle: itself when it has a front winding number, else the nearest
    /// triangle across edges that has one, or -1 (SurfaceSideView::stand_in).
    std::vector<int32_t> stand_in;
    double min_distance = 0;     ///< SurfaceSideView::min_distance
    int components = 0;          ///< edge-connected components of triangles in no intersecting pair
    int components_decided = 0;  ///< those whose front winding number was certified
    int components_from_outside = 0;  ///< of them, read from outside the mesh's box (no sum)
    int64_t triangles_known = 0; ///< triangles with a front winding number
    double seconds = 0;
    std::string why_off;         ///< empty when the table is on

    SurfaceSideView view() const {
        return front_winding.empty() ? SurfaceSideView{} : SurfaceSideView{front_winding.data(), stand_in.data(), min_distance};
    }
};

/// The table of `mesh` on `threads` threads (0: all). At most kSurfaceSideComponents
/// components are evaluated (the largest; each costs a direct sum over the mesh), the
/// others' triangles stay unknown.
SurfaceSides build_surface_sides(const PreparedMesh& mesh, int threads = 0);

constexpr int kSurfaceSideComponents = 32;

}  // namespace sdf
