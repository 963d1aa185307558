#include "experiments/common/reconstruction_list.h"

#include <algorithm>
#include <stdexcept>

#include "core/quoted_alternatives.h"

namespace sdf {
namespace {

size_t find_lattice(JsonReader& r, const std::string& name, const std::vector<LatticeSpec>& lattices,
                    const std::vector<std::string>& labels) {
    for (size_t i = 0; i < labels.size(); ++i)
        if (labels[i] == name) return i;
    std::vector<size_t> of_type;
    for (size_t i = 0; i < lattices.size(); ++i)
        if (name == lattice_type_name(lattices[i].type)) of_type.push_back(i);
    const std::string list = quoted_alternatives(labels);
    if (of_type.size() == 1) return of_type[0];
    if (of_type.size() > 1)
        r.fail("lattice", "\"" + name + "\" is ambiguous: " + std::to_string(of_type.size()) + " lattices have that type; name one of " + list);
    const std::string near = nearest_match(name, labels);
    r.fail("lattice", "names no lattice: \"" + name + "\"; expected one of " + list + " (or \"cc\" / \"bcc\")" +
                          (near.empty() ? "" : " (did you mean \"" + near + "\"?)"));
}

ReconstructionEntry entry(size_t lattice, const std::string& label, InterpolatorKind kind, DerivativeSource source) {
    ReconstructionEntry e;
    e.lattice = lattice;
    e.spec.interpolator = kind;
    e.spec.derivatives = source;
    e.id = label + "/" + interpolator_name(kind) + "/" + derivative_source_name(source);
    e.thesis_panel = thesis_panel(e.spec);
    return e;
}

/// Checks `e` against its lattice as the reconstruction will (validate_reconstruction).
void check_entry(JsonReader& r, const ReconstructionEntry& e, const LatticeSpec& lattice) {
    Lattice l;
    l.type = lattice.type;
    l.resolution = lattice_spec_resolution(lattice);
    try {
        validate_reconstruction(e.spec, l, /*field_has_gradient=*/true);
    } catch (const std::invalid_argument& err) {
        r.fail("interpolator", err.what());
    }
}

}  // namespace

std::string thesis_panel(const ReconstructionSpec& s) {
    const bool truth = s.derivatives == DerivativeSource::True, fd = s.derivatives == DerivativeSource::FiniteDifferences;
    switch (s.interpolator) {
        case kind_of<CatmullRom>(): return "A";
        case kind_of<BccCubic>(): return truth ? "B" : fd ? "C" : "";
        case kind_of<TricubicLekienMarsden>(): return truth ? "D" : fd ? "E" : "";
        default: return "";
    }
}

/// Every filter of the lattice's type in table order, with each derivative source except
/// fd_weighted (a variant of the fit with its own parameter; name it explicitly).
std::vector<ReconstructionEntry> every_filter(size_t lattice, const std::string& label, LatticeType type) {
    std::vector<ReconstructionEntry> out;
    for (int k = 0; k < kInterpolatorKinds; ++k) {
        const InterpolatorKind kind = InterpolatorKind(k);
        if (interpolator_lattice(kind) != type) continue;
        for (DerivativeSource source : valid_derivative_sources(kind))
            if (source != DerivativeSource::FiniteDifferencesWeighted) out.push_back(entry(lattice, label, kind, source));
    }
    return out;
}

std::vector<ReconstructionEntry> read_reconstructions(JsonReader& config, const std::vector<LatticeSpec>& lattices,
                                                      const std::vector<std::string>& labels) {
    std::vector<ReconstructionEntry> out;
    const bool named_set = config.has("reconstructions") && config.json().at("reconstructions").is_string();
    const std::string set = named_set ? config.choice("reconstructions", {"thesis", "all"}, "thesis") : "thesis";
    if (!config.has("reconstructions") || named_set) {
        for (size_t i = 0; i < lattices.size(); ++i) {
            if (set == "all") {
                for (ReconstructionEntry& e : every_filter(i, labels[i], lattices[i].type)) {
                    Lattice l;
                    l.type = lattices[i].type;
                    l.resolution = lattice_spec_resolution(lattices[i]);
                    try {
                        validate_reconstruction(e.spec, l, /*field_has_gradient=*/true);
                    } catch (const std::invalid_argument& err) {
                        config.fail("reconstructions", "\"all\" includes " + e.id + ", which does not fit lattice \"" +
                                                           labels[i] + "\": " + err.what() + "; name the reconstructions instead");
                    }
                    out.push_back(std::move(e));
                }
            } else if (lattices[i].type == LatticeType::CC) {
                out.push_back(entry(i, labels[i], kind_of<Trilinear>(), DerivativeSource::FiniteDifferences));
                out.push_back(entry(i, labels[i], kind_of<CatmullRom>(), DerivativeSource::FiniteDifferences));
                out.push_back(entry(i, labels[i], kind_of<TricubicLekienMarsden>(), DerivativeSource::True));
                out.push_back(entry(i, labels[i], kind_of<TricubicLekienMarsden>(), DerivativeSource::FiniteDifferences));
            } else {
                out.push_back(entry(i, labels[i], kind_of<BccLinear>(), DerivativeSource::FiniteDifferences));
                out.push_back(entry(i, labels[i], kind_of<BccCubic>(), DerivativeSource::True));
                out.push_back(entry(i, labels[i], kind_of<BccCubic>(), DerivativeSource::FiniteDifferences));
            }
        }
        nlohmann::json all = nlohmann::json::array();
        for (const ReconstructionEntry& x : out)
            all.push_back({{"lattice", labels[x.lattice]},
                           {"interpolator", interpolator_name(x.spec.interpolator)},
                           {"derivatives", derivative_source_name(x.spec.derivatives)}});
        config.record("reconstructions", all);
        return out;
    }
    std::vector<JsonReader> entries = config.objects("reconstructions");
    if (entries.empty()) config.fail("reconstructions", "expected at least one reconstruction, got []");
    for (JsonReader& r : entries) {
        const size_t li = find_lattice(r, r.required<std::string>("lattice", "a lattice name or type"), lattices, labels);
        const InterpolatorKind kind = parse_interpolator(r.choice("interpolator", interpolator_names(), "trilinear"));
        const std::string fallback = derivative_source_name(default_derivative_source(kind, true));
        ReconstructionEntry e = entry(li, labels[li], kind,
                                      parse_derivative_source(r.choice("derivatives", {"true", "fd", "fd_weighted"}, fallback)));
        e.spec.sigma2 = r.optional<double>("sigma2", 0.5, "sigma^2 of the Gaussian weights (fd_weighted, thesis eq. 4-15)");
        if (!(e.spec.sigma2 > 0)) r.fail("sigma2", "expected a positive number, got " + std::to_string(e.spec.sigma2));
        e.spec.sigma_units = r.choice("sigma_units", {"lattice", "spacing"}, "lattice") == "lattice" ? SigmaUnits::LatticeUnits
                                                                                                     : SigmaUnits::Spacing;
        if (e.spec.derivatives == DerivativeSource::FiniteDifferencesWeighted)
            e.id += "-sigma2_" + nlohmann::json(e.spec.sigma2).dump() + (e.spec.sigma_units == SigmaUnits::Spacing ? "h2" : "");
        check_entry(r, e, lattices[li]);
        r.finish();
        for (const ReconstructionEntry& other : out)
            if (other.id == e.id) r.fail("interpolator", "the same reconstruction as an earlier entry (" + e.id + ")");
        out.push_back(e);
    }
    return out;
}

}  // namespace sdf
