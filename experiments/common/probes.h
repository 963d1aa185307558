/// @file probes.h
/// @brief Probe points for reconstruction errors, with the exact signed distance and
/// gradient at each, and the error figures of a reconstruction at them.
///
/// Two sets, both deterministic for a seed: "domain" probes, uniform in a box (the domain
/// every compared reconstruction covers), and "band" probes near the surface: a random
/// surface point (area-weighted triangle, uniform barycentric), moved along the face normal
/// by a uniform offset in [-w, w]. The exact distance comes from the sampler's query(); a
/// probe counts as "in the band" when its exact |d| <= w (a band probe can end up closer to
/// another part of the surface; domain probes that fall in the band count there too).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/prepared_mesh.h"
#include "core/sampling/sampler.h"
#include "kernels/reconstruction/interpolator.h"

namespace sdf {

class ContentCache;

/// Bump when probe placement changes, so cached probe sets are no longer found.
constexpr int kProbeCodeVersion = 1;

struct ProbeSpec {
    int64_t domain_probes = 100000;
    int64_t band_probes = 100000;
    double band = 1.0;   ///< band half-width in units of the reference spacing
    uint64_t seed = 1;
};

struct ProbeSet {
    std::vector<Vec3d> points;
    std::vector<double> distance;  ///< exact signed distance
    std::vector<Vec3d> gradient;   ///< exact gradient (unit)
    int64_t domain_count = 0;      ///< points[0, domain_count) are the domain probes
    double band_width = 0;         ///< w, in mesh units
    bool in_band(size_t i) const { return std::abs(distance[i]) <= band_width; }
};

/// Places the probes in `box` and computes their exact distances with the sampler bound to
/// the mesh that `sampler()` gives, called only then (or takes the whole set from `cache`
/// when it holds it; a null cache is not used). `log_line` receives one line saying which.
ProbeSet make_probes(const PreparedMesh& mesh, const DomainBox<double>& box, double band_width, const ProbeSpec& spec,
                     const std::function<const BoundSampler&()>& sampler, const SamplerOptions& sampler_options,
                     const ContentCache* cache, std::string* log_line);

/// Error figures of reconstructed samples against the exact values at the probes:
///   domain: rms, max_abs, mean_abs over the domain probes;
///   band: rms, max_abs, mean_abs over every probe in the band, and the angle between the
///   reconstructed and the exact gradient there (mean and 95th percentile, degrees);
///   max_abs over all probes (L-infinity).
nlohmann::json probe_errors(const ProbeSet& probes, const std::vector<ReconstructedSample<double>>& got);

}  // namespace sdf
