/// @file sparse_band_cells.h
/// @brief Which world points a sparse narrow band (sparse_band.h) holds exact values
/// around: the rule a reconstruction of the band applies before it trusts a value (Python's
/// SparseField.reconstruct, sdf-eval on a sparse band's file; docs/field-format.md).
#pragma once

#include "core/sampling/sparse_band.h"

namespace sdf {

/// Whether `p` lies in the band's cells: for every coset of the lattice (CC: one grid; BCC:
/// the primary grid and the secondary one, h/2 off), the 8 corners of the coset's cell that
/// holds p are lattice points within the band (points of active blocks with |d| <= W, their
/// closest triangle set). A reconstruction there reads exact values for its cell; a wider
/// stencil may still read points beyond the band, which hold +-W as in the dense `--band W`
/// field (its reconstruction is the dense one's). False outside the lattice.
bool in_band_cells(const SparseBandField& band, const Vec3d& p);

}  // namespace sdf
