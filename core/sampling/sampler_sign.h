/// @file sampler_sign.h
/// @brief The sign step every sampler shares (CPU and CUDA): resolve the requested sign mode
/// for the mesh when the sampler is bound to it (auto: choose_sign_mode on its preparation
/// report, with a warning on stderr that says why when it picks winding), build the winding
/// sign then, and record the choice in the field's provenance. Distances and gradients stay exact; in winding mode
/// only their side changes (with_sign), in pseudonormal mode nothing does.
#pragma once

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "core/mesh/prepared_mesh.h"
#include "core/winding/surface_sides.h"
#include "core/winding/winding_sign.h"
#include "kernels/winding/with_sign.h"

namespace sdf {

class SamplerSign {
public:
    explicit SamplerSign(SignMode requested = SignMode::Auto) : requested_(requested) {}

    /// Resolves the mode for `mesh` (from its own report) and, for winding, builds its
    /// WindingSign over the mesh's BVH (the warning is written then). Called once, when a
    /// sampler is bound to the mesh (core/sampling/backend_sampler.h); not thread-safe.
    const SignModeChoice& prepare(const PreparedMesh& mesh);

    /// Resolves the mode as prepare() does but builds no host winding sign: for a sampler
    /// that computes the winding moments itself (the CUDA BVH sampler's device build), which
    /// calls it when it builds them (the warning is written then) and reports their time with
    /// set_external_moments(). winding_sign() stays null.
    const SignModeChoice& prepare_mode(const PreparedMesh& mesh);
    /// Seconds the external moments took and where they were built, for provenance().
    void set_external_moments(double seconds, const std::string& built_on) {
        external_moments_seconds_ = seconds;
        external_moments_on_ = built_on;
    }

    SignMode requested() const { return requested_; }
    const SignModeChoice& choice() const { return choice_; }
    bool winding() const { return choice_.mode == SignMode::Winding; }
    /// The winding sign of the prepared mesh; null unless the mode resolved to winding.
    const WindingSign* winding_sign() const { return winding_.get(); }

    /// `s` (evaluated at p) with the winding number's certified side in winding mode, the
    /// point counted in `counts` by how its side was decided; unchanged otherwise. `near`:
    /// the certified search's candidates at p (nearest_side, surface_side.h), if known.
    SignedDistanceSample<double> apply(const SignedDistanceSample<double>& s, const Vec3d& p, WindingSignCounts& counts,
                                       const NearTriangles& near = {}) const {
        if (!winding()) return s;
        bool inside = false;
        if (winding_->options().nearest_sides &&
            nearest_side(surface_view(), winding_->view(), p, s.triangle, s.distance, s.closest_point, near, inside)) {
            counts.add(WindingStage::Nearest);
            return with_sign(s, inside);
        }
        if (surface_side(surface_view(), winding_->view(), p, s.triangle, s.distance, inside)) {
            counts.add(WindingStage::Surface);
            return with_sign(s, inside);
        }
        const WindingSide side = winding_->side(p);
        counts.add(side.stage);
        return with_sign(s, side.inside);
    }

    /// The mesh's table of sides from the closest triangle (surface_sides.h), in winding mode
    /// when winding_options() asks for it; otherwise off (no table).
    SurfaceSideView surface_view() const { return surface_ ? surface_->view() : SurfaceSideView{}; }

    /// {"requested", "mode", "reason"} and, in winding mode, "winding": {"beta", "order",
    /// "moments_seconds"}: for the field's sampler provenance.
    nlohmann::json provenance() const;

    /// The winding sign every backend uses (WindingSignOptions' default: certified, first
    /// evaluation beta 2, order 2, then certified_winding.h's ladder): every backend and tree
    /// gives the exact side of 1/2 of the winding number, ties outside. For measurement only,
    /// SDF_WINDING_LADDER_ONLY=1 leaves the first stage's table out (the same sides), and
    /// SDF_WINDING_UNCERTIFIED=1 the certification (the fast value's side: the uncertified
    /// kernel the certified one is timed against; the provenance's "certified": false and
    /// the field cache's key say so).
    static WindingSignOptions winding_options();

    /// The prepared mesh's largest |coordinate| (WindingView::scale, for device views).
    double mesh_scale() const { return mesh_scale_; }

private:
    SignMode requested_;
    SignModeChoice choice_;
    std::shared_ptr<const WindingSign> winding_;
    std::shared_ptr<const SurfaceSides> surface_;
    double external_moments_seconds_ = 0;
    std::string external_moments_on_;  ///< empty: the moments are winding_'s
    double mesh_scale_ = 0;
};

/// "sign auto for mesh 'NAME' (SOURCE): REASON" when `sampler` (a field's sampler
/// provenance) records that auto chose the winding sign, else "": the warning prepare()
/// writes, for fields read back from the cache.
std::string auto_sign_warning(const nlohmann::json& sampler, const PreparedMesh& mesh);

}  // namespace sdf
