#include "core/sampling/sampler_sign.h"

#include "core/parallel/task_monitor.h"

namespace sdf {
namespace {

std::string auto_sign_text(const PreparedMesh& mesh, const std::string& reason) {
    return "sign auto for mesh '" + mesh.name() + "' (" + mesh.source() + "): " + reason;
}

}  // namespace

const SignModeChoice& SamplerSign::prepare_mode(const PreparedMesh& mesh) {
    choice_ = choose_sign_mode(mesh.report(), requested_);
    winding_.reset();
    external_moments_on_.clear();
    if (requested_ == SignMode::Auto && choice_.mode == SignMode::Winding)
        report_warning(auto_sign_text(mesh, choice_.reason));
    return choice_;
}

const SignModeChoice& SamplerSign::prepare(const PreparedMesh& mesh) {
    choice_ = choose_sign_mode(mesh.report(), requested_);
    external_moments_on_.clear();
    winding_.reset();
    if (choice_.mode != SignMode::Winding) return choice_;
    if (requested_ == SignMode::Auto) report_warning(auto_sign_text(mesh, choice_.reason));
    winding_ = std::make_shared<const WindingSign>(mesh, mesh.bvh(), winding_options());
    return choice_;
}

nlohmann::json SamplerSign::provenance() const {
    nlohmann::json p = {{"requested", sign_mode_name(requested_)},
                        {"mode", sign_mode_name(choice_.mode)},
                        {"reason", choice_.reason}};
    if (winding_) {
        const WindingSignOptions o = winding_options();
        p["winding"] = {{"beta", o.accuracy.beta},
                        {"order", o.accuracy.order},
                        {"certified", o.certify},
                        {"moments_seconds", winding_->winding_bvh().seconds}};
    } else if (winding() && !external_moments_on_.empty()) {
        const WindingSignOptions o = winding_options();
        p["winding"] = {{"beta", o.accuracy.beta},
                        {"order", o.accuracy.order},
                        {"certified", o.certify},
                        {"moments_seconds", external_moments_seconds_},
                        {"moments_built_on", external_moments_on_}};
    }
    return p;
}

std::string auto_sign_warning(const nlohmann::json& sampler, const PreparedMesh& mesh) {
    if (!sampler.is_object() || !sampler.contains("sign")) return "";
    const nlohmann::json& sign = sampler.at("sign");
    if (sign.value("requested", "") != "auto" || sign.value("mode", "") != "winding") return "";
    return auto_sign_text(mesh, sign.value("reason", ""));
}

}  // namespace sdf
