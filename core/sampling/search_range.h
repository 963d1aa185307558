/// @file search_range.h
/// @brief The coordinates a nearest-triangle search can answer to its precision, and a
/// refusal, naming the mesh or the query, for everything beyond (issue 11, class 2).
///
/// Every search compares squared distances. In float they overflow beyond 2^64 and lose
/// their relative precision to underflow below 2^-126 (about 1e-38): a point 1e20 from the
/// origin, or a mesh of coordinates 1e20..1e38, gave infinities that no triangle could beat
/// (a crash), and a mesh 1e-20 across gave squared distances in the denormals, where the
/// nearest triangle is lost (distances off by factors of 1-2). The float search is therefore
/// limited to coordinates of magnitude at most 2^60 (squared distances at most 2^124) and to
/// meshes at least 2^-40 across (squared distances of a millionth of the mesh still 2^-120
/// and normal); double to 2^500 and 2^-450. Within these ranges a double search returns the
/// double argmin of squared_distance() (ties to the smaller index), and a certified float
/// search (kernels/distance/search_certificate.h: every sampler but the thesis's CUDA kernel
/// and the CPU "eberly" kernel) returns that same triangle; the winner is evaluated in double,
/// so distance, sign and gradient are bit for bit the double run's
/// (docs/architecture-floating-point.md, "Precision contract"). The sign of a point outside
/// the mesh's bounding box is "outside" (MeshView::box_lo), which far from the mesh is where
/// the search cannot tell the nearest triangle from one on the far side.
#pragma once

#include <string>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "core/sampling/host_query.h"
#include "core/sampling/sampled_field.h"

namespace sdf {

/// The largest coordinate magnitude and the smallest mesh extent a search in `precision`
/// answers.
double largest_search_coordinate(Precision precision);
double smallest_search_extent(Precision precision);

/// Throws std::invalid_argument unless the mesh and the lattice's points are in range.
void require_search_range(const PreparedMesh& mesh, const Lattice& lattice, Precision precision);
/// Throws std::invalid_argument unless the mesh and every point are in range (and finite),
/// naming the first point that is not; the points are scanned on `threads` threads (0: all).
void require_search_range(const PreparedMesh& mesh, const std::vector<Vec3d>& points, Precision precision,
                          int threads = 1);
void require_search_range(const PreparedMesh& mesh, const HostPoints& points, Precision precision, int threads = 1);
/// Throws std::invalid_argument unless the mesh is in range.
void require_search_range(const PreparedMesh& mesh, Precision precision);
/// Throws std::invalid_argument naming query point `index` (0-based) unless p is finite and in range.
void require_query_point_in_range(const Vec3d& p, int64_t index, Precision precision);

}  // namespace sdf
