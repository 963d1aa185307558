#include "core/sampling/sampler_sign.h"

#include <cstdlib>

#include "core/parallel/task_monitor.h"

namespace sdf {
namespace {

std::string auto_sign_text(const PreparedMesh& mesh, const std::string& reason) {
    return "sign auto for mesh '" + mesh.name() + "' (" + mesh.source() + "): " + reason;
}

/// Whether the environment variable `name` is "1" (the measurement switches below).
bool switched_on(const char* name) {
    const char* v = std::getenv(name);
    return v != nullptr && std::string(v) == "1";
}

/// The table of sides from the closest triangle (surface_sides.h), the certified sign's first
/// stage, where winding_options() asks for it.
std::shared_ptr<const SurfaceSides> surface_sides_for(const PreparedMesh& mesh) {
    const WindingSignOptions o = SamplerSign::winding_options();
    if (!o.certify || !o.surface_sides) return nullptr;
    return std::make_shared<const SurfaceSides>(build_surface_sides(mesh));
}

}  // namespace

/// Three measurement switches, read at binding (not per point): SDF_WINDING_LADDER_ONLY=1 leaves
/// the table out (the ladder alone: the baseline the table is measured against; the same
/// sides, only the cost differs), SDF_WINDING_WALK_ONLY=1 the side from the nearest
/// triangles alone (every table side walks the tree), SDF_WINDING_UNCERTIFIED=1 the
/// certification.
WindingSignOptions SamplerSign::winding_options() {
    WindingSignOptions o;
    o.certify = !switched_on("SDF_WINDING_UNCERTIFIED");
    o.surface_sides = !switched_on("SDF_WINDING_LADDER_ONLY");
    o.nearest_sides = !switched_on("SDF_WINDING_WALK_ONLY");
    return o;
}

const SignModeChoice& SamplerSign::prepare_mode(const PreparedMesh& mesh) {
    choice_ = choose_sign_mode(mesh.report(), requested_);
    winding_.reset();
    surface_.reset();
    external_moments_on_.clear();
    mesh_scale_ = winding_scale(mesh);
    if (choice_.mode != SignMode::Winding) return choice_;
    if (requested_ == SignMode::Auto) report_warning(auto_sign_text(mesh, choice_.reason));
    surface_ = surface_sides_for(mesh);
    return choice_;
}

const SignModeChoice& SamplerSign::prepare(const PreparedMesh& mesh) {
    choice_ = choose_sign_mode(mesh.report(), requested_);
    external_moments_on_.clear();
    winding_.reset();
    surface_.reset();
    mesh_scale_ = winding_scale(mesh);
    if (choice_.mode != SignMode::Winding) return choice_;
    if (requested_ == SignMode::Auto) report_warning(auto_sign_text(mesh, choice_.reason));
    winding_ = std::make_shared<const WindingSign>(mesh, mesh.bvh(), winding_options());
    surface_ = surface_sides_for(mesh);
    return choice_;
}

namespace {

nlohmann::json surface_sides_json(const SurfaceSides& s) {
    if (!s.why_off.empty()) return {{"used", false}, {"why", s.why_off}};
    return {{"used", true},
            {"components", s.components},
            {"components_decided", s.components_decided},
            {"components_from_outside", s.components_from_outside},
            {"triangles_known", s.triangles_known},
            {"seconds", s.seconds}};
}

nlohmann::json winding_accuracy_json(const WindingSignOptions& o) {
    nlohmann::json j = {{"beta", o.accuracy.beta}, {"order", o.accuracy.order}, {"certified", o.certify}};
    if (o.certify)
        j["certification"] = {{"refine_factor", o.certification.refine_factor},
                              {"refinements", o.certification.refinements},
                              {"ties", "outside"}};
    return j;
}

}  // namespace

nlohmann::json SamplerSign::provenance() const {
    nlohmann::json p = {{"requested", sign_mode_name(requested_)},
                        {"mode", sign_mode_name(choice_.mode)},
                        {"reason", choice_.reason}};
    if (winding_) {
        p["winding"] = winding_accuracy_json(winding_options());
        p["winding"]["moments_seconds"] = winding_->winding_bvh().seconds;
    } else if (winding() && !external_moments_on_.empty()) {
        p["winding"] = winding_accuracy_json(winding_options());
        p["winding"]["moments_seconds"] = external_moments_seconds_;
        p["winding"]["moments_built_on"] = external_moments_on_;
    }
    if (p.contains("winding") && surface_) p["winding"]["surface_sides"] = surface_sides_json(*surface_);
    return p;
}

std::string auto_sign_warning(const nlohmann::json& sampler, const PreparedMesh& mesh) {
    if (!sampler.is_object() || !sampler.contains("sign")) return "";
    const nlohmann::json& sign = sampler.at("sign");
    if (sign.value("requested", "") != "auto" || sign.value("mode", "") != "winding") return "";
    return auto_sign_text(mesh, sign.value("reason", ""));
}

}  // namespace sdf
