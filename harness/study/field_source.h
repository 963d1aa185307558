/// @file field_source.h
/// @brief The one "field from cache or sampler" path of every front end: run-experiment's
/// studies and sdf-render (with the field cache), sdf-sample (its sampler, for the streamed
/// slabs) and the Python module's sample() (no cache). A field comes from the field cache
/// when it holds it, else it is sampled (the sampler is made and bound to the mesh on first
/// use, and kept while the same mesh is asked for) and stored in the
/// cache at once, so an interrupted run resumes without sampling again; an allocation that
/// fails while sampling names the mesh, the lattice and the bytes. A narrow band (the
/// sampler's band_width > 0, a config's "band_width") is sampled sparsely
/// (BoundSampler::sample_band_sparse, only the blocks within W of a triangle; over the ranks
/// of a distributed run, densely as before) and densified:
/// the dense band's field byte for byte; the cache keeps its sparse file (FieldCache::store_band).
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

/// Where a field's sampler runs.
enum class SamplerReach {
    Ranks,        ///< over the ranks of a distributed run (make_field_sampler); this process alone without one
    ThisProcess,  ///< on this process alone (make_sampler): sdf-sample, the module's sample(distributed=False)
};

class FieldSource {
public:
    /// A run's source: its field cache (none with --no-cache) and its config named in errors.
    FieldSource(const RunContext& context, SamplerOptions options);
    /// `cache` null: every field is sampled. `where` prefixes the errors of the sampler's
    /// making ("<config>: key 'sampler'", "the command line").
    FieldSource(const FieldCache* cache, SamplerOptions options, std::string where,
                SamplerReach reach = SamplerReach::Ranks);
    ~FieldSource();

    /// "cached" or "to sample" (with "--no-cache" when the cache is off), for plans.
    std::string status(const PreparedMesh& mesh, const Lattice& lattice) const;
    /// The field of `mesh` on `lattice`; `label` names it in the log.
    ObtainedField get(const std::shared_ptr<const PreparedMesh>& mesh, const Lattice& lattice, const std::string& label,
                      std::ostream& log);
    /// The sampler bound to `mesh` (made and bound on first use; bound again when another
    /// mesh is asked for), e.g. for exact distances at probe points or streamed slabs.
    const BoundSampler& bound(const std::shared_ptr<const PreparedMesh>& mesh);
    const SamplerOptions& options() const { return options_; }

private:
    const FieldCache* cache_;
    SamplerOptions options_;
    std::unique_ptr<Sampler> sampler_;
    std::unique_ptr<BoundSampler> bound_;  ///< sampler_ bound to the mesh of the last call
    std::string where_;  ///< "<config>: key 'sampler'", for errors of the sampler's making
    SamplerReach reach_;
};

}  // namespace sdf
