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
            "closed, manifold, consistently oriented, one shell, no self-intersections, no slivers within the search's "
            "rounding: pseudonormal signs are exact"};
}

WindingSign::WindingSign(const PreparedMesh& mesh, const WindingSignOptions& options)
    : WindingSign(mesh, mesh.bvh(), options) {}

WindingSign::WindingSign(const PreparedMesh& mesh, std::shared_ptr<const TriangleBvh> bvh, const WindingSignOptions& options)
    : WindingSign(mesh, build_winding_bvh(mesh, std::move(bvh)), options) {}

WindingSign::WindingSign(const PreparedMesh& mesh, WindingBvh winding, const WindingSignOptions& options)
    : options_(options), winding_(std::move(winding)) {
    if (!(options.accuracy.beta > 1.0))
        throw std::invalid_argument("winding sign: beta must be > 1 (the far field needs d > r), got " +
                                    std::to_string(options.accuracy.beta));
    if (options.accuracy.order != 1 && options.accuracy.order != 2)
        throw std::invalid_argument("winding sign: order must be 1 or 2, got " + std::to_string(options.accuracy.order));
    if (options.certify && !(options.certification.refine_factor > 1.0))
        throw std::invalid_argument("winding sign: refine_factor must be > 1, got " +
                                    std::to_string(options.certification.refine_factor));
    if (options.certify && options.certification.refinements < 0)
        throw std::invalid_argument("winding sign: refinements must be >= 0, got " +
                                    std::to_string(options.certification.refinements));
    view_ = winding_.view<double>(mesh);
}

WindingEstimate<double> WindingSign::estimate(const Vec3d& p, const WindingAccuracy<double>& accuracy) const {
    return fast_winding_number(view_, p, accuracy);
}

WindingSide WindingSign::side(const Vec3d& p) const {
    if (!options_.certify) {
        return {fast_winding_number(view_, p, options_.accuracy).value > 0.5, WindingStage::Fast};
    }
    return certified_winding_side(view_, p, options_.accuracy, options_.certification);
}

WindingSide WindingSign::side_after(const Vec3d& p, double fast_value, double fast_bound) const {
    WindingSide s{fast_value > 0.5, WindingStage::Fast};
    if (options_.certify && !winding_decides(WindingEstimate<double>{fast_value, fast_bound, 0}))
        s = certified_winding_refine(view_, p, options_.accuracy, options_.certification);
    return s;
}

}  // namespace sdf
