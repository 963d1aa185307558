/// @file exact_predicates.h
/// @brief Exact geometric predicates on double coordinates: the answers are those of exact
/// (rational) arithmetic on the input doubles, never of rounded determinants. They come from
/// CGAL's Exact_predicates_inexact_constructions_kernel (a floating-point filter with an exact
/// fallback), compiled in one translation unit (exact_predicates.cpp) so that no other file
/// pays CGAL's compile cost or sees its types.
///
/// Why exact: a segment lying on the line of a triangle's edge (collinear edges of CAD
/// models, planar regions split into fans) makes the orientation determinants exactly 0; in
/// doubles they come out as tiny values of either sign, and a self-intersection test built on
/// them reports touching or distant pairs as crossing.
#pragma once

#include "kernels/core/vec3.h"

namespace sdf::exact {

/// Sign of det[b - a, c - a, d - a] (+1, 0, -1): which side of plane abc the point d is on.
int orientation(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d);

/// a, b, c lie on one line (a triangle abc of zero area).
bool collinear(const Vec3d& a, const Vec3d& b, const Vec3d& c);

/// For coplanar a, b, c, d with a, b, c not collinear: +1 when d is on the same side of the
/// line ab as c, 0 on the line, -1 on the other side (CGAL::coplanar_orientation).
int coplanar_orientation(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d);

/// The closed segment pq meets the closed, non-degenerate triangle (t0 t1 t2).
bool segment_meets_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& t0, const Vec3d& t1, const Vec3d& t2);

/// The closed, non-degenerate triangles (a0 a1 a2) and (b0 b1 b2) have a common point.
bool triangles_meet(const Vec3d a[3], const Vec3d b[3]);

}  // namespace sdf::exact
