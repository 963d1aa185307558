#include "harness/config/lattice_spec.h"

#include "cpu_reference/lattice/lattice_fitting.h"

namespace sdf {

const char* lattice_type_name(LatticeType t) { return t == LatticeType::CC ? "cc" : "bcc"; }

LatticeSpec parse_lattice_spec(JsonReader& r) {
    LatticeSpec spec;
    spec.type = r.choice("type", {"cc", "bcc"}, "cc") == "cc" ? LatticeType::CC : LatticeType::BCC;
    const bool has_res = r.has("resolution"), has_samples = r.has("samples");
    if (has_res == has_samples) r.fail(has_res ? "samples" : "resolution", "give exactly one of \"resolution\" and \"samples\"");
    if (has_res) {
        const auto res = r.required<std::vector<int>>("resolution", "an array of 3 integers >= 2");
        if (res.size() != 3 || res[0] < 2 || res[1] < 2 || res[2] < 2)
            r.fail("resolution", "expected an array of 3 integers >= 2");
        spec.resolution = {res[0], res[1], res[2]};
        if (spec.type == LatticeType::BCC) {
            if (res[2] % 2 != 0 || res[2] < 4)
                r.fail("resolution", "BCC resolution is written [Rx, Ry, 2Rz]; the third entry must be even and >= 4, got " +
                                         std::to_string(res[2]));
            spec.resolution = bcc_primary_from_notation(spec.resolution);
        }
    } else {
        spec.samples = r.required<int64_t>("samples", "a target number of lattice points");
        if (spec.samples < 8) r.fail("samples", "expected at least 8 points, got " + std::to_string(spec.samples));
    }
    spec.margin = r.optional<double>("margin", -1.0, "a margin as a fraction of the mesh's largest extent");
    return spec;
}

Lattice build_lattice(const LatticeSpec& spec, const Bounds3& bounds, double default_margin) {
    Int3 res = spec.resolution;
    if (spec.samples > 0) {
        const int r = cubic_resolution_for_samples(spec.type, spec.samples);
        res = {r, r, r};
    }
    return fit_lattice(spec.type, res, bounds, spec.margin >= 0 ? spec.margin : default_margin);
}

}  // namespace sdf
