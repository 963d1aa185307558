/// @file reconstruction_list.h
/// @brief The "reconstructions" of a config: which interpolator, with which derivative
/// source, on which of the config's lattices; and the thesis's default set.
///
///   "reconstructions": [
///     {"lattice": "cc", "interpolator": "catmull_rom"},
///     {"lattice": "bcc", "interpolator": "bcc_cubic", "derivatives": "true"},
///     {"lattice": "bcc-64x64x128", "interpolator": "bcc_cubic", "derivatives": "fd_weighted",
///      "sigma2": 0.5, "sigma_units": "lattice"}]
/// "lattice" is a lattice label (lattice_spec.h) or a type when exactly one lattice has it.
/// "derivatives" defaults to "true" for interpolators that read derivatives, else "fd".
/// Without "reconstructions" (or "reconstructions": "thesis"): on every CC lattice trilinear,
/// catmull_rom, tricubic_lm/true, tricubic_lm/fd; on every BCC lattice bcc_linear,
/// bcc_cubic/true, bcc_cubic/fd: the five of thesis Figures 5-2..5-11 plus the two linear
/// baselines. "reconstructions": "all": every filter of the interpolator table on every
/// lattice of its type, with each derivative source but fd_weighted (box splines, B-spline,
/// bcc_cubic_c0 beside the thesis's set; issue 17).
#pragma once

#include <string>
#include <vector>

#include "core/reconstruction/reconstruction_spec.h"
#include "harness/config/json_reader.h"
#include "harness/config/lattice_spec.h"

namespace sdf {

struct ReconstructionEntry {
    std::string id;        ///< "<lattice label>/<interpolator>/<derivatives>"
    size_t lattice = 0;    ///< index into the config's lattices
    ReconstructionSpec spec;
    std::string thesis_panel;  ///< "A".."E" in thesis Figures 5-2..5-11, or ""
};

/// Reads config["reconstructions"] (or makes the default set); checks every entry against
/// its lattice (type, derivative source, smallest resolution) with errors naming the key.
std::vector<ReconstructionEntry> read_reconstructions(JsonReader& config, const std::vector<LatticeSpec>& lattices,
                                                      const std::vector<std::string>& labels);

/// The panel of thesis Figures 5-2..5-11: A catmull_rom, B bcc_cubic/true, C bcc_cubic/fd,
/// D tricubic_lm/true, E tricubic_lm/fd; "" for the others.
std::string thesis_panel(const ReconstructionSpec& spec);

}  // namespace sdf
