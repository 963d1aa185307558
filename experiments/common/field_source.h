/// @file field_source.h
/// @brief Sampled fields for an experiment: from the field cache when it holds them, else
/// sampled (the sampler is made on first use) and stored in the cache at once, so an
/// interrupted run resumes without sampling again.
#pragma once

#include <iosfwd>
#include <memory>
#include <string>

#include "core/mesh/prepared_mesh.h"
#include "core/sampling/sampler.h"
#include "harness/experiment/experiment.h"

namespace sdf {

struct ObtainedField {
    SampledField field;
    bool from_cache = false;
    std::string cache_key;  ///< SHA-256 of the cache key
    nlohmann::json describe() const;  ///< lattice, points, cache key, cached or sampled, timings
};

class FieldSource {
public:
    FieldSource(const RunContext& context, SamplerOptions options);
    ~FieldSource();

    /// "cached" or "to sample" (with "--no-cache" when the cache is off), for plans.
    std::string status(const PreparedMesh& mesh, const Lattice& lattice) const;
    /// The field of `mesh` on `lattice`; `label` names it in the log.
    ObtainedField get(const PreparedMesh& mesh, const Lattice& lattice, const std::string& label, std::ostream& log);
    /// The sampler (made on first use), e.g. for exact distances at probe points.
    Sampler& sampler();
    const SamplerOptions& options() const { return options_; }

private:
    const FieldCache* cache_;
    SamplerOptions options_;
    std::unique_ptr<Sampler> sampler_;
    std::string where_;  ///< "<config>: key 'sampler'", for errors of the sampler's making
};

}  // namespace sdf
