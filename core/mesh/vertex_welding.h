/// @file vertex_welding.h
/// @brief Welding a mesh's input vertices, preparation's first step (prepared_mesh.h), and the
/// check a refit makes that new positions weld as the first preparation's did.
#pragma once

#include <vector>

#include "kernels/core/vec3.h"

namespace sdf {

/// Maps every input vertex to a welded vertex id, the ids numbered in order of first
/// appearance; `out` receives each welded vertex's position (its first input vertex's). With
/// tolerance 0 only positions that compare equal merge; otherwise a vertex merges into the
/// first kept vertex within `tolerance` (searched in the 27 grid cells of size `tolerance`
/// around it), so closeness and not grid alignment decides.
std::vector<int> weld_vertices(const std::vector<Vec3d>& in, double tolerance, std::vector<Vec3d>& out);

/// Whether weld_vertices(in, 0, ...) gives `weld` (a tolerance-0 welding of as many vertices),
/// decided without its map of lists: it does exactly when every vertex equals the first of its
/// group and the groups' first vertices are pairwise different (one pass, and one
/// open-addressing table of the firsts). On true, `welded` receives the positions
/// weld_vertices would. False also where a position is not finite: weld_vertices decides then.
bool welds_like(const std::vector<Vec3d>& in, const std::vector<int>& weld, std::vector<Vec3d>& welded, int threads);

}  // namespace sdf
