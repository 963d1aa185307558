/// @file lattice_fitting.h
/// @brief Places a lattice around a mesh, and matches CC and BCC sample counts.
///
/// The domain is the mesh's bounding box grown by `margin` times its largest extent on every
/// side. The spacing is isotropic: the axis that needs the widest spacing decides it, and
/// the lattice is centred on the box, so a cubic resolution covers a cube around the mesh.
#pragma once

#include <cstdint>
#include <string>

#include "core/mesh/triangle_mesh.h"
#include "kernels/lattice/lattice.h"

namespace sdf {

/// `resolution` is the CC resolution, or for BCC the primary grid (Rx, Ry, Rz).
Lattice fit_lattice(LatticeType type, Int3 resolution, const Bounds3& bounds, double margin);

/// The largest lattice any tool samples or reads: 2^36 points (16 bytes each with a gradient
/// channel: 1 TiB), far beyond any machine's memory but far from int64 overflow.
constexpr int64_t kMaxLatticePoints = int64_t(1) << 36;

/// The number of points of a lattice of `type` with primary resolution `resolution`, in
/// checked arithmetic; throws std::invalid_argument when a resolution entry is below 1 or the
/// count exceeds kMaxLatticePoints (an overflowing count included).
int64_t checked_lattice_points(LatticeType type, Int3 resolution);

/// Thesis notation: "80x80x80" for CC, "Rx x Ry x 2Rz" = "64x64x128" for BCC.
std::string lattice_notation(const Lattice& lattice);

/// Thesis notation [Rx, Ry, 2Rz] -> primary resolution (Rx, Ry, Rz); throws if 2Rz is odd.
Int3 bcc_primary_from_notation(Int3 notation);

/// Number of points of a cubic lattice of resolution r (CC r^3; BCC r^3 + (r-1)^3).
int64_t cubic_lattice_points(LatticeType type, int r);

/// The cubic resolution whose point count is nearest to `samples` (thesis: CC 80^3 = 512,000
/// matches BCC 64x64x128 = 512,191).
int cubic_resolution_for_samples(LatticeType type, int64_t samples);

}  // namespace sdf
