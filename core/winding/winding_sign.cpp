#include "core/winding/winding_sign.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace sdf {

const char* sign_mode_name(SignMode mode) {
    for (const NamedSignMode& m : kSignModes)
        if (m.mode == mode) return m.name;
    throw std::logic_error("sign mode without a name in kSignModes");
}

std::vector<std::string> sign_mode_names() {
    std::vector<std::string> names;
    for (const NamedSignMode& m : kSignModes) names.emplace_back(m.name);
    return names;
}

SignMode sign_mode_from_name(const std::string& name, const std::string& where) {
    for (const NamedSignMode& m : kSignModes)
        if (name == m.name) return m.mode;
    std::string expected;
    const std::vector<std::string> names = sign_mode_names();
    for (size_t i = 0; i < names.size(); ++i)
        expected += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + ("\"" + names[i] + "\"");
    throw std::invalid_argument(where + ": unknown sign mode '" + name + "'; expected " + expected);
}

SignModeChoice choose_sign_mode(const MeshReport& r, SignMode requested) {
    if (requested != SignMode::Auto) return {requested, std::string(sign_mode_name(requested)) + " requested"};
    // The report's one rule (MeshReport::sign_unreliable_reason), which sign_reliable() shares.
    const std::string why = r.sign_unreliable_reason();
    if (!why.empty())
        return {SignMode::Winding, why + ": pseudonormal signs are not reliable there; using the winding number"};
    return {SignMode::Pseudonormal,
            "closed, manifold, consistently oriented, one shell, no self-intersections: pseudonormal signs are exact"};
}

WindingSign::WindingSign(const PreparedMesh& mesh, const WindingSignOptions& options)
    : WindingSign(mesh, mesh.bvh(), options) {}

WindingSign::WindingSign(const PreparedMesh& mesh, std::shared_ptr<const TriangleBvh> bvh, const WindingSignOptions& options)
    : options_(options), winding_(build_winding_bvh(mesh, std::move(bvh))) {
    if (!(options.accuracy.beta > 1.0))
        throw std::invalid_argument("winding sign: beta must be > 1 (the far field needs d > r), got " +
                                    std::to_string(options.accuracy.beta));
    if (options.accuracy.order != 1 && options.accuracy.order != 2)
        throw std::invalid_argument("winding sign: order must be 1 or 2, got " + std::to_string(options.accuracy.order));
    if (options.certify && !(options.refine_factor > 1.0))
        throw std::invalid_argument("winding sign: refine_factor must be > 1, got " + std::to_string(options.refine_factor));
    view_ = winding_.view<double>(mesh);
}

WindingEstimate<double> WindingSign::estimate(const Vec3d& p, const WindingAccuracy<double>& accuracy) const {
    return fast_winding_number(view_, p, accuracy);
}

bool WindingSign::inside(const Vec3d& p) const {
    WindingEstimate<double> e = estimate(p);
    if (!options_.certify) return e.value > 0.5;
    const auto certain = [](const WindingEstimate<double>& x) { return std::abs(x.value - 0.5) > x.error_bound; };
    if (certain(e)) return e.value > 0.5;
    ++refined_;
    WindingAccuracy<double> finer = options_.accuracy;
    for (int k = 0; k < options_.max_refinements; ++k) {
        finer.beta *= options_.refine_factor;
        e = estimate(p, finer);
        if (certain(e)) return e.value > 0.5;
    }
    ++exact_;
    finer.beta = std::numeric_limits<double>::infinity();
    return estimate(p, finer).value > 0.5;
}

}  // namespace sdf
