/// @file lattice_spec.h
/// @brief A lattice as a config writes it, and its placement around a mesh.
///
///   {"type": "cc",  "resolution": [80, 80, 80]}
///   {"type": "bcc", "resolution": [64, 64, 128]}   thesis notation Rx x Ry x 2Rz
///   {"type": "bcc", "samples": 512000}             cubic, point count nearest to 512,000
#pragma once

#include "cpu_reference/mesh/triangle_mesh.h"
#include "harness/config/json_reader.h"
#include "kernels/lattice/lattice.h"

namespace sdf {

struct LatticeSpec {
    LatticeType type = LatticeType::CC;
    Int3 resolution{};     ///< CC resolution or BCC primary (Rx, Ry, Rz); zero when `samples` is used
    int64_t samples = 0;   ///< target point count for a cubic lattice
    double margin = -1;    ///< per-lattice margin override; < 0 = the config's domain margin
};

LatticeSpec parse_lattice_spec(JsonReader& r);
/// The lattice of `spec` around `bounds` (margin as in fit_lattice).
Lattice build_lattice(const LatticeSpec& spec, const Bounds3& bounds, double default_margin);
const char* lattice_type_name(LatticeType t);

}  // namespace sdf
