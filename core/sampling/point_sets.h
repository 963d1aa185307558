/// @file point_sets.h
/// @brief Arbitrary query point sets around a mesh, drawn reproducibly from a seed: uniform
/// in the mesh's box expanded by a margin, and Gaussian around surface points as neural-SDF
/// training-data generators draw them (an area-weighted random triangle, a uniform point on
/// it, plus an N(0, sigma^2) offset per axis; e.g. DeepSDF, Park et al. CVPR 2019, samples
/// near the surface this way). The random numbers are SplitMix64 with our own uniform and
/// Box-Muller transforms, so a seed gives the same points with any standard library.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/mesh/prepared_mesh.h"

namespace sdf {

enum class PointSetKind { UniformBox, GaussianSurface };

/// One point set: its kind, size and parameters.
struct PointSetSpec {
    PointSetKind kind = PointSetKind::UniformBox;
    int64_t count = 0;
    double sigma = 0.01;   ///< GaussianSurface: the offset's standard deviation, a fraction of the mesh's bounding-box diagonal
    double margin = 0.1;   ///< UniformBox: the box's margin, a fraction of the mesh's largest extent (as lattices are fitted)
    uint64_t seed = 1;
};

/// The kinds' config names: "uniform_box", "gaussian_surface".
const char* point_set_kind_name(PointSetKind kind);
/// Throws std::invalid_argument naming the expected names for an unknown one.
PointSetKind point_set_kind_from_name(const std::string& name);
/// "uniform_box/1048576" or "gaussian_surface(sigma=0.01)/1048576".
std::string point_set_label(const PointSetSpec& spec);

/// The points of `spec` around `mesh` (the same for the same spec and mesh).
std::vector<Vec3d> make_point_set(const PreparedMesh& mesh, const PointSetSpec& spec);

}  // namespace sdf
