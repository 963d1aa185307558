/// @file surface_side.h
/// @brief The winding number's side of a point read from its closest triangle, on a closed
/// mesh that intersects itself: the certified sign's shortcut where the tree's far field would
/// need many refinements (points near the surface). Host and device.
///
/// On a closed, consistently oriented mesh the generalized winding number w is an integer off
/// the surface, constant on each connected region of the complement, and one larger behind a
/// triangle than in front of it (its solid angle jumps by 4 pi across it). A point p whose
/// closest point c lies on triangle T at distance d > 0 sees no surface in the open ball of
/// radius d about it, so w(p) is the winding number of the region beside c on p's side. Where
/// no other triangle touches T or the triangles around its corners (none is in an
/// intersecting pair), none of them is a sliver or folded flat against its neighbour and
/// those corners are manifold, that side is
/// the pseudonormal's
/// (Baerentzen & Aanaes 2005: the sign of the sample's distance), and the region in front of T
/// is the one in front of every triangle reachable from T across edges without meeting an
/// intersecting triangle. So one certified evaluation per such component of the mesh gives
/// `front_winding`, and then
///   w(p) = front_winding[T] + (p behind T),      inside  <=>  w(p) >= 1  (w > 1/2).
/// Exact in exact arithmetic only: the closest triangle found by rounded searches and the
/// rounded pseudonormal's side can be wrong beside surfaces an ulp apart or at needle corners,
/// so the samplers use it only where asked (SDF_WINDING_SURFACE_SIDES=1, docs/winding.md).
/// The table is built once per mesh (core/winding/surface_sides.h); triangles it cannot vouch
/// for hold kSurfaceSideUnknown and their points take the ladder (certified_winding.h), as do
/// points within `min_distance` of the surface, where the ladder's tie rule holds.
#pragma once

#include <cmath>
#include <cstdint>

#include "kernels/core/vec3.h"

namespace sdf {

constexpr int8_t kSurfaceSideUnknown = INT8_MIN;

/// Plain pointers to a mesh's table (host or device); no table (front_winding null): off.
struct SurfaceSideView {
    const int8_t* front_winding = nullptr;  ///< per prepared triangle, or kSurfaceSideUnknown
    double min_distance = 0;               ///< |d| at or below this: the ladder decides
};

/// Decides `inside` from the closest triangle and the sample's pseudonormal-signed distance;
/// false when the table cannot (no table, no triangle, a triangle it does not vouch for, a
/// point on the surface to within min_distance).
SDF_CPU_GPU SDF_INLINE bool surface_side(const SurfaceSideView& v, int triangle, double pseudonormal_distance,
                                         bool& inside) {
    if (v.front_winding == nullptr || triangle < 0) return false;
    const int8_t front = v.front_winding[triangle];
    if (front == kSurfaceSideUnknown || !(fabs(pseudonormal_distance) > v.min_distance)) return false;
    inside = int(front) + (pseudonormal_distance < 0.0 ? 1 : 0) >= 1;
    return true;
}

}  // namespace sdf
