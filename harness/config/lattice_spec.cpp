#include "harness/config/lattice_spec.h"

#include <algorithm>
#include <regex>

#include "core/lattice/lattice_fitting.h"

namespace sdf {

LatticeSpec parse_lattice_spec(JsonReader& r, LatticeStorage storage) {
    LatticeSpec spec;
    spec.type = lattice_type_named(r.choice("type", lattice_type_names(), lattice_type_name(LatticeType::CC)));
    const bool has_res = r.has("resolution"), has_samples = r.has("samples");
    if (has_res == has_samples) r.fail(has_res ? "samples" : "resolution", "give exactly one of \"resolution\" and \"samples\"");
    if (has_res) {
        const auto res = r.required<std::vector<int>>("resolution", "an array of 3 integers >= 2");
        if (res.size() != 3 || res[0] < 2 || res[1] < 2 || res[2] < 2)
            r.fail("resolution", "expected an array of 3 integers >= 2, got " + r.raw("resolution").dump());
        spec.resolution = {res[0], res[1], res[2]};
        if (spec.type == LatticeType::BCC) {
            if (res[2] % 2 != 0 || res[2] < 4)
                r.fail("resolution", "BCC resolution is written [Rx, Ry, 2Rz]; the third entry must be even and >= 4, got " +
                                         std::to_string(res[2]));
            spec.resolution = bcc_primary_from_notation(spec.resolution);
        }
        try {
            checked_lattice_points(spec.type, spec.resolution, storage);
        } catch (const std::invalid_argument& e) {
            r.fail("resolution", e.what());
        }
    } else {
        spec.samples = r.required<int64_t>("samples", "a target number of lattice points");
        if (spec.samples < 8) r.fail("samples", "expected at least 8 points, got " + std::to_string(spec.samples));
        if (spec.samples > max_lattice_points(storage))
            r.fail("samples", std::string("expected at most ") + (storage == LatticeStorage::Dense ? "2^36" : "2^42") +
                                  " points, got " + std::to_string(spec.samples));
    }
    if (r.has("margin")) {
        spec.margin = r.required<double>("margin", "a margin as a fraction of the mesh's largest extent");
        if (!(spec.margin >= 0))
            r.fail("margin", "expected a non-negative fraction of the mesh's largest extent, got " + r.raw("margin").dump());
    }
    if (r.has("name")) {
        spec.name = r.required<std::string>("name", "a lattice name of letters, digits, '-', '_' or '.'");
        if (!std::regex_match(spec.name, std::regex("[A-Za-z0-9][A-Za-z0-9_.-]*")))
            r.fail("name", "expected letters, digits, '-', '_' or '.', starting with a letter or digit, got \"" +
                               spec.name + "\"");
    }
    return spec;
}

Int3 lattice_spec_resolution(const LatticeSpec& spec) {
    if (spec.samples <= 0) return spec.resolution;
    const int r = cubic_resolution_for_samples(spec.type, spec.samples);
    return {r, r, r};
}

std::string lattice_spec_notation(const LatticeSpec& spec) {
    Lattice l;
    l.type = spec.type;
    l.resolution = lattice_spec_resolution(spec);
    return std::string(lattice_type_name(spec.type)) + " " + lattice_notation(l);
}

Lattice build_lattice(const LatticeSpec& spec, const Bounds3& bounds, double default_margin, LatticeStorage storage) {
    return fit_lattice(spec.type, lattice_spec_resolution(spec), bounds, spec.margin >= 0 ? spec.margin : default_margin,
                       storage);
}

std::vector<std::string> lattice_spec_labels(const std::vector<LatticeSpec>& specs, const JsonReader& r,
                                             const std::string& key) {
    std::vector<std::string> labels;
    for (size_t i = 0; i < specs.size(); ++i) {
        const std::string here = key + "[" + std::to_string(i) + "]";
        if (!specs[i].name.empty()) {
            const auto same = std::find(labels.begin(), labels.end(), specs[i].name);
            if (same != labels.end())
                throw ConfigError(r.file() + ": key '" + r.key_path(here) + ".name': \"" + specs[i].name +
                                  "\" is already the name of " + key + "[" + std::to_string(same - labels.begin()) +
                                  "]; lattice names must be unique");
            labels.push_back(specs[i].name);
            continue;
        }
        std::string label = lattice_spec_notation(specs[i]);
        label[label.find(' ')] = '-';
        if (std::find(labels.begin(), labels.end(), label) != labels.end()) label += "-" + std::to_string(i);
        labels.push_back(label);
    }
    // A derived label may still equal a later given name: check once more.
    for (size_t i = 0; i < labels.size(); ++i)
        for (size_t j = i + 1; j < labels.size(); ++j)
            if (labels[i] == labels[j])
                throw ConfigError(r.file() + ": key '" + r.key_path(key + "[" + std::to_string(j) + "]") +
                                  "': its name \"" + labels[j] + "\" is also the name of " + key + "[" +
                                  std::to_string(i) + "]; give the lattices distinct \"name\"s");
    return labels;
}

}  // namespace sdf
