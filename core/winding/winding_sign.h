/// @file winding_sign.h
/// @brief Resolving a sign mode (sign_mode.h) for a mesh, and the CPU per-point sign from
/// the generalized winding number.
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "core/winding/sign_mode.h"
#include "core/winding/winding_bvh.h"
#include "kernels/winding/certified_winding.h"

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
    /// Beta and order of the first (fast) evaluation: Barill et al.'s default, beta 2, order 2.
    WindingAccuracy<double> accuracy;
    /// Certify every sign (certified_winding.h): the side of 1/2 of the exact winding number,
    /// proven by the fast evaluation's rigorous bound, else by `certification`'s stricter
    /// opening rules, else by the direct sum; ties (w within the direct sum's bound of 1/2)
    /// outside. Off: the fast value's side (tree-dependent; kept for measurements).
    bool certify = true;
    WindingCertification certification;
    /// With certify: first read the side of a point of a closed mesh from its closest
    /// triangle where the table of core/winding/surface_sides.h vouches for it (the same
    /// exact side, without the far field's refinements near the surface). Off: every point
    /// takes the ladder (its tests).
    bool surface_sides = true;
    /// With the table: first the side from the search's nearest triangles alone, where the
    /// search is certified (nearest_side, surface_side.h: no walk of the tree). Off: the
    /// walk (its measurements).
    bool nearest_sides = true;
};

/// Points signed, by how their side was decided (certified_winding.h's ladder).
struct WindingSignCounts {
    int64_t fast = 0, refined = 0, direct = 0, ties = 0, surface = 0, nearest = 0;
    void add(WindingStage stage, int64_t n = 1) {
        switch (stage) {
        case WindingStage::Fast: fast += n; break;
        case WindingStage::Refined: refined += n; break;
        case WindingStage::Direct: direct += n; break;
        case WindingStage::Tie: ties += n; break;
        case WindingStage::Surface: surface += n; break;
        case WindingStage::Nearest: nearest += n; break;
        }
    }
    int64_t points() const { return fast + refined + direct + ties + surface + nearest; }
    WindingSignCounts& operator+=(const WindingSignCounts& o) {
        fast += o.fast;
        refined += o.refined;
        direct += o.direct;
        ties += o.ties;
        surface += o.surface;
        nearest += o.nearest;
        return *this;
    }
    WindingSignCounts operator-(const WindingSignCounts& o) const {
        return {fast - o.fast, refined - o.refined, direct - o.direct, ties - o.ties, surface - o.surface, nearest - o.nearest};
    }
    bool operator==(const WindingSignCounts& o) const {
        return fast == o.fast && refined == o.refined && direct == o.direct && ties == o.ties && surface == o.surface &&
               nearest == o.nearest;
    }
};

/// WindingSignCounts that several threads add to (each its own, once per chunk): a
/// sampling's counters (core/sampling/backend_sampler.h's SlabRun).
struct SharedWindingCounts {
    std::atomic<int64_t> n[kWindingStages] = {};
    void add(const WindingSignCounts& c) {
        n[int(WindingStage::Fast)] += c.fast;
        n[int(WindingStage::Refined)] += c.refined;
        n[int(WindingStage::Direct)] += c.direct;
        n[int(WindingStage::Tie)] += c.ties;
        n[int(WindingStage::Surface)] += c.surface;
        n[int(WindingStage::Nearest)] += c.nearest;
    }
    WindingSignCounts load() const {
        return {n[int(WindingStage::Fast)].load(), n[int(WindingStage::Refined)].load(),
                n[int(WindingStage::Direct)].load(), n[int(WindingStage::Tie)].load(),
                n[int(WindingStage::Surface)].load(), n[int(WindingStage::Nearest)].load()};
    }
};

/// The CPU winding-number sign of one mesh: build once, call inside() from any thread.
class WindingSign {
public:
    /// Over the mesh's own BVH (PreparedMesh::bvh()).
    WindingSign(const PreparedMesh& mesh, const WindingSignOptions& options = {});
    /// Over `bvh`, a BVH of `mesh` (mesh.bvh(), the host emulation of the GPU's tree, ...).
    WindingSign(const PreparedMesh& mesh, std::shared_ptr<const TriangleBvh> bvh, const WindingSignOptions& options = {});
    /// Over a tree of `mesh` with its moments already computed (e.g. the GPU build's host
    /// emulation, core/bvh/lbvh.h, whose moments are the device's bits).
    WindingSign(const PreparedMesh& mesh, WindingBvh winding, const WindingSignOptions& options = {});

    /// The side of p and how it was decided: certified, or the fast value's side. Callers
    /// count the stages (WindingSignCounts) where they report them: the sign keeps no
    /// per-call state, so concurrent samplings of one bound sampler count apart.
    WindingSide side(const Vec3d& p) const;
    /// The same, given the first evaluation's value and bound at p (certified_winding_number
    /// at options().accuracy, whose bits a packet's lanes have).
    WindingSide side_after(const Vec3d& p, double fast_value, double fast_bound) const;
    /// True when w(p) > 1/2 (side(p).inside).
    bool inside(const Vec3d& p) const { return side(p).inside; }

    /// The fast evaluation at `accuracy` (beta = +infinity: the exact sum), uncertified bound.
    WindingEstimate<double> estimate(const Vec3d& p, const WindingAccuracy<double>& accuracy) const;
    WindingEstimate<double> estimate(const Vec3d& p) const { return estimate(p, options_.accuracy); }

    const WindingBvh& winding_bvh() const { return winding_; }
    /// What inside() evaluates: for evaluations of several points at once that must give the
    /// same sides (the CPU's packets, fast_winding_packet.h).
    const WindingView<double>& view() const { return view_; }
    const WindingSignOptions& options() const { return options_; }

private:
    WindingSignOptions options_;
    WindingBvh winding_;
    WindingView<double> view_;
};

}  // namespace sdf
