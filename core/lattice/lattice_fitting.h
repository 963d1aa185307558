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

/// How a lattice's values are held, which bounds how large it may be.
enum class LatticeStorage {
    Dense,       ///< every point (a field, its files, a reconstruction): memory grows with the lattice
    SparseBand,  ///< only the blocks of a sparse narrow band (core/sampling/sparse_band.h): memory grows with the band
};

/// The largest lattice any tool samples or reads as `storage`: dense 2^36 points (16 bytes
/// each with a gradient channel: 1 TiB, beyond any machine's memory); a sparse band 2^42
/// (16384^3), whose cost is its band's but whose per-block bitsets (one bit per 8^3 block)
/// take 1 GiB each there. Both far from int64 overflow.
constexpr int64_t max_lattice_points(LatticeStorage storage) {
    switch (storage) {
    case LatticeStorage::Dense: return int64_t(1) << 36;
    case LatticeStorage::SparseBand: return int64_t(1) << 42;
    }
    return 0;
}
constexpr int64_t kMaxLatticePoints = max_lattice_points(LatticeStorage::Dense);

/// `resolution` is the CC resolution, or for BCC the primary grid (Rx, Ry, Rz); its point
/// count is checked against `storage`'s largest lattice.
Lattice fit_lattice(LatticeType type, Int3 resolution, const Bounds3& bounds, double margin,
                    LatticeStorage storage = LatticeStorage::Dense);

/// The number of points of a lattice of `type` with primary resolution `resolution`, in
/// checked arithmetic; throws std::invalid_argument when a resolution entry is below 1 or the
/// count exceeds max_lattice_points(storage) (an overflowing count included).
int64_t checked_lattice_points(LatticeType type, Int3 resolution, LatticeStorage storage = LatticeStorage::Dense);

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
