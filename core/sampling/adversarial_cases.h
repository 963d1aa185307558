/// @file adversarial_cases.h
/// @brief Meshes and query points where a float nearest-triangle search is most easily
/// wrong: near-ties between triangles whose float squared distances differ by less than
/// their rounding (the certified search's property test, tests/cpu_reference/bvh/
/// certified_search_test.cpp, and the fuzz battery run them against the double brute force).
///
/// Meshes: a unit cube whose faces are split by a diagonal; a CAD-like closed plate (large
/// planar faces triangulated as fans, strips along sides with collinear edges); a strip of
/// thin slivers near the sliver threshold; slivers of every size (make_sliver_zoo); copies of the cube and the plate 1e3 and 1e5 from
/// the origin; a box with a sphere 5e-4 above its face and a nested inner box. Points: near
/// edges (the cube's diagonals among them), vertices and faces, 1e-5 .. 1e-2 (relative to
/// the mesh) above them, plus a few farther out. Reproducible from a seed (SplitMix64).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh/triangle_mesh.h"

namespace sdf {

struct AdversarialCase {
    TriangleMesh mesh;
    std::vector<Vec3d> points;
};

/// A closed CAD-like plate of half-size `half` and half-thickness `half * 0.1` centred at
/// `center`: top and bottom are fans around an interior vertex over `per_side` collinear
/// boundary vertices a side, the sides strips of two triangles a boundary segment.
TriangleMesh make_fan_plate(int per_side, double half, Vec3d center = {});

/// Slivers of every size beside neighbours: needles (angle at the apex) and caps (angles at
/// both ends of the long edge) of 1e-2, 1e-3, ..., 1e-8 degrees, `length` long, one group a
/// 3 `length` step along x, each with neighbours folded 0.05 `length` below its plane along
/// its edges; points on each sliver, 1e-9 .. 0.3 `length` above and below it, beside its
/// edges and around its vertices (issue 38: such slivers were ranked by their edges only).
AdversarialCase make_sliver_zoo(double length, uint64_t seed, int points_per_sliver);

/// Every case, `points_per_case` points each (the sliver zoos about that many in all).
std::vector<AdversarialCase> adversarial_cases(uint64_t seed, int points_per_case);

/// Points near the features of `mesh` (edges, vertices, faces), as adversarial_cases() draws them.
std::vector<Vec3d> adversarial_points(const TriangleMesh& mesh, uint64_t seed, int count);

}  // namespace sdf
