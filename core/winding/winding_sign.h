/// @file winding_sign.h
/// @brief Resolving a sign mode (sign_mode.h) for a mesh, and the CPU per-point sign from
/// the generalized winding number.
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "core/winding/sign_mode.h"
#include "core/winding/winding_bvh.h"

namespace sdf {

struct SignModeChoice {
    SignMode mode = SignMode::Pseudonormal;
    std::string reason;  ///< why, for the run's warnings and manifest
};

/// Resolves `requested` for a mesh with this preparation report: Auto becomes Pseudonormal
/// when the mesh is closed, manifold, consistently oriented, a single shell and free of
/// self-intersections, and Winding otherwise, with the first reason that ruled it out.
SignModeChoice choose_sign_mode(const MeshReport& report, SignMode requested = SignMode::Auto);

struct WindingSignOptions {
    /// Beta and order of the fast evaluation. Barill et al.'s default (beta 2, order 2)
    /// costs about a fifth of the unsigned BVH query on the dragon (docs in the report).
    WindingAccuracy<double> accuracy;
    /// Certify every sign against the rigorous error bound: where |w - 1/2| is within it,
    /// evaluate again with beta times refine_factor (up to `max_refinements` times), then
    /// exactly. The bound is pessimistic (it sums worst cases over the accepted children),
    /// so certification costs several fast evaluations; off, the sign is the fast value's.
    bool certify = false;
    double refine_factor = 2.0;
    int max_refinements = 3;
};

/// The CPU winding-number sign of one mesh: build once, call inside() from any thread.
class WindingSign {
public:
    /// Over the mesh's own BVH (PreparedMesh::bvh()).
    WindingSign(const PreparedMesh& mesh, const WindingSignOptions& options = {});
    /// Over `bvh`, a BVH of `mesh` (mesh.bvh(), or a tree built with other options).
    WindingSign(const PreparedMesh& mesh, std::shared_ptr<const TriangleBvh> bvh, const WindingSignOptions& options = {});

    /// True when w(p) > 1/2: the fast value's side of 1/2, or with `certify` the side
    /// proven by the error bound (beta raised where needed, last the exact sum).
    bool inside(const Vec3d& p) const;

    /// The fast evaluation at `accuracy` (beta = +infinity: the exact sum).
    WindingEstimate<double> estimate(const Vec3d& p, const WindingAccuracy<double>& accuracy) const;
    WindingEstimate<double> estimate(const Vec3d& p) const { return estimate(p, options_.accuracy); }

    /// With `certify`: points whose sign needed a larger beta, or the exact sum.
    int64_t refined() const { return refined_.load(); }
    int64_t exact_evaluations() const { return exact_.load(); }

    const WindingBvh& winding_bvh() const { return winding_; }
    /// What inside() evaluates: for evaluations of several points at once that must give the
    /// same sides (the CPU's packets, fast_winding_packet.h).
    const WindingView<double>& view() const { return view_; }
    const WindingSignOptions& options() const { return options_; }

private:
    WindingSignOptions options_;
    WindingBvh winding_;
    WindingView<double> view_;
    mutable std::atomic<int64_t> refined_{0}, exact_{0};
};

}  // namespace sdf
