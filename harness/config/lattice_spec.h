/// @file lattice_spec.h
/// @brief A lattice as a config writes it, and its placement around a mesh.
///
///   {"type": "cc",  "resolution": [80, 80, 80]}
///   {"type": "bcc", "resolution": [64, 64, 128]}   thesis notation Rx x Ry x 2Rz
///   {"type": "bcc", "samples": 512000}             cubic, point count nearest to 512,000
///   optional: "margin" (>= 0, overrides the config's domain margin), "name" (the label that
///   names the lattice's field files and that reconstructions refer to)
#pragma once

#include <string>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/triangle_mesh.h"
#include "harness/config/json_reader.h"
#include "kernels/lattice/lattice.h"

namespace sdf {

struct LatticeSpec {
    LatticeType type = LatticeType::CC;
    Int3 resolution{};     ///< CC resolution or BCC primary (Rx, Ry, Rz); zero when `samples` is used
    int64_t samples = 0;   ///< target point count for a cubic lattice
    double margin = -1;    ///< per-lattice margin override; < 0 = the config's domain margin
    std::string name;      ///< as written; "" = derived (lattice_spec_labels)
};

/// Reads a lattice, its size checked against `storage`'s largest lattice (max_lattice_points).
LatticeSpec parse_lattice_spec(JsonReader& r, LatticeStorage storage = LatticeStorage::Dense);
/// The lattice of `spec` around `bounds` (margin as in fit_lattice), held as `storage`.
Lattice build_lattice(const LatticeSpec& spec, const Bounds3& bounds, double default_margin,
                      LatticeStorage storage = LatticeStorage::Dense);
// Lattice types by name: lattice_type_name(), lattice_type_named() (kernels/lattice/lattice_kinds.h).

/// The resolution `spec` will have (CC resolution or BCC primary), known without a mesh.
Int3 lattice_spec_resolution(const LatticeSpec& spec);
/// "cc 80x80x80" / "bcc 64x64x128" (thesis notation), known without a mesh.
std::string lattice_spec_notation(const LatticeSpec& spec);

/// One unique label per lattice, in order: the "name" when given, else "cc-80x80x80"; a
/// derived label that repeats an earlier one gets the suffix "-<index>". Throws ConfigError
/// (naming `r`'s file and "lattices[i].name") when two given names collide.
std::vector<std::string> lattice_spec_labels(const std::vector<LatticeSpec>& specs, const JsonReader& r,
                                             const std::string& key = "lattices");

}  // namespace sdf
