/// @file lattice_points.h
/// @brief Lattice points as point lists for Sampler::query and the peer libraries: every
/// point, or an evenly strided subset timed in place of the whole lattice (brute force
/// costs the same per point, so its time scales by N / n).
#pragma once

#include <cstdint>
#include <vector>

#include "kernels/lattice/lattice.h"

namespace sdf {

/// Every point of `lattice`, in storage order.
std::vector<Vec3d> lattice_points(const Lattice& lattice);

struct LatticeSubset {
    std::vector<int64_t> index;  ///< lattice index of each point
    std::vector<Vec3d> points;
};

/// `count` points of `lattice` (all when count <= 0 or beyond the lattice), every
/// (N / count)-th in storage order from index 0.
LatticeSubset strided_lattice_subset(const Lattice& lattice, int64_t count);

}  // namespace sdf
