/// @file procedural_shapes.h
/// @brief Closed, outward-oriented test shapes the project generates itself: an icosphere,
/// a box, a torus, a chess pawn (thesis Fig. 5-1 E, ~300 triangles) and a soccer ball
/// (thesis Fig. 5-1 A, ~3,500 triangles, truncated icosahedron with engraved seams).
/// Every generator is deterministic, so the same parameters give bit-identical meshes.
#pragma once

#include <string>

#include "core/mesh/triangle_mesh.h"

namespace sdf {

/// Icosahedron subdivided `subdivisions` times and projected on the sphere: 20 * 4^k triangles.
TriangleMesh make_icosphere(int subdivisions, double radius = 1.0, Vec3d center = {});

/// Axis-aligned box with the given half extents, 2 triangles per face (12 in all).
TriangleMesh make_box(Vec3d half_extent = {1.0, 1.0, 1.0}, Vec3d center = {});

/// Torus around the z axis: `major_segments` around the axis, `minor_segments` around the tube.
TriangleMesh make_torus(double major_radius = 1.0, double minor_radius = 0.35, int major_segments = 64,
                        int minor_segments = 32);

/// Chess pawn as a surface of revolution about the y axis, about 1 unit tall; with the
/// default `segments` it has about 300 triangles, as the thesis's pawn (304).
TriangleMesh make_pawn(int segments = 16);

/// Soccer ball of radius 1: a truncated icosahedron (12 pentagons, 20 hexagons) on the
/// sphere, with seams engraved `seam_depth` deep and `seam_width` wide (radians); about
/// 3,500 triangles at the default `detail`, as the thesis's ball (3,516).
TriangleMesh make_soccer_ball(int detail = 2, double seam_depth = 0.02, double seam_width = 0.03);

}  // namespace sdf
