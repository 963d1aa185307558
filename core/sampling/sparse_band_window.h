/// @file sparse_band_window.h
/// @brief A box of a sparse narrow band's lattice (sparse_band.h) as a small dense field: what
/// SparseBandField::densify() holds at those points, without the rest of the lattice. A
/// reconstruction of the band (core/reconstruction/sparse_reconstruction.h) builds its
/// derivative data on such windows, so its memory grows with the band, not the lattice.
#pragma once

#include "core/sampling/sparse_band.h"

namespace sdf {

/// A sub-lattice of a lattice: the primary points [first, first + resolution) per axis and,
/// on BCC, the secondary points between them (secondary index first .. first + resolution - 2),
/// as the lattice of its own with the same type and spacing, its origin at primary point
/// `first`.
struct LatticeWindow {
    Int3 first{};
    Int3 resolution{};

    /// The window's own lattice (origin = the parent's primary point `first`).
    Lattice lattice_in(const Lattice& parent) const;
    /// Whether the window lies within `parent` and has at least one point per axis.
    bool fits(const Lattice& parent) const;
};

/// The window of `band`'s lattice, densified: every point holds the densified band's
/// distance, gradient and closest triangle (store order of the window's lattice). Without
/// `gradient` the field has no gradient channel (as densify_within_memory without it); the
/// gradient of a band read without one is 0, as densify() gives; a band without the closest
/// triangle gives a field without one (an empty `closest_triangle`). Throws
/// std::invalid_argument when the window does not fit the lattice.
SampledField densify_window(const SparseBandField& band, const LatticeWindow& window, bool gradient);

}  // namespace sdf
