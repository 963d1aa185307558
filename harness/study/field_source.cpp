#include "harness/study/field_source.h"

#include <cstdio>
#include <iostream>
#include <optional>
#include <ostream>

#include "core/lattice/lattice_fitting.h"
#include "core/sampling/sampler_sign.h"
#include "harness/study/study_inputs.h"
#include "harness/cache/field_cache.h"
#include "harness/distributed/distributed.h"
#include "harness/io/field_file.h"
#include "harness/resources/memory_budget.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {

nlohmann::json ObtainedField::describe() const {
    const SamplingTimings& t = field.timings;
    return {{"lattice", lattice_to_json(field.lattice)},
            {"cache_key", cache_key},
            {"from_cache", from_cache},
            {"sampler", field.sampler},
            {"seconds", t.total},
            {"kernel_seconds", t.kernel},
            {"pairs_per_second", t.pairs_per_second()}};
}

FieldSource::FieldSource(const RunContext& context, SamplerOptions options)
    : FieldSource(context.fields, std::move(options), context.config_path + ": key 'sampler'") {}

FieldSource::FieldSource(const FieldCache* cache, SamplerOptions options, std::string where, SamplerReach reach)
    : cache_(cache), options_(std::move(options)), where_(std::move(where)), reach_(reach) {}

FieldSource::~FieldSource() = default;

const BoundSampler& FieldSource::bound(const std::shared_ptr<const PreparedMesh>& mesh) {
    if (!sampler_) {
        try {
            // Split over the ranks of a distributed run, or this process's alone.
            sampler_ = reach_ == SamplerReach::Ranks ? make_field_sampler(options_) : make_sampler(options_);
        } catch (const std::exception& e) {
            throw std::runtime_error(where_ + ": " + e.what());
        }
    }
    // bound_ holds its mesh, so the comparison is of owners, never of a freed mesh's address.
    if (!bound_ || bound_->shared_mesh() != mesh) {
        bound_.reset();  // the last mesh's device memory first
        bound_ = sampler_->bind(mesh);
    }
    return *bound_;
}

std::string FieldSource::status(const PreparedMesh& mesh, const Lattice& lattice) const {
    if (!cache_) return "to sample (--no-cache)";
    const nlohmann::json key = field_cache_key(mesh.content_sha256(), lattice, options_);
    return cache_->contains(key) ? "cached " + ContentCache::key_hash(key).substr(0, 12) : "to sample";
}

ObtainedField FieldSource::get(const std::shared_ptr<const PreparedMesh>& shared_mesh, const Lattice& lattice,
                               const std::string& label, std::ostream& log) {
    const PreparedMesh& mesh = *shared_mesh;
    ObtainedField out;
    const nlohmann::json key = field_cache_key(mesh.content_sha256(), lattice, options_);
    out.cache_key = ContentCache::key_hash(key);
    const std::string what = label + " (" + lattice_notation(lattice) + ", " + with_commas(lattice.num_points()) + " points)";
    if (cache_) {
        if (std::optional<SampledField> f = cache_->load(key)) {
            log << "  " << what << ": from the cache (" << out.cache_key.substr(0, 12) << ")\n";
            const std::string sign_warning = auto_sign_warning(f->sampler.details, mesh);
            if (!sign_warning.empty()) std::cerr << "warning: " << sign_warning << "\n";
            out.field = std::move(*f);
            out.from_cache = true;
            return out;
        }
    }
    const BoundSampler& sampler = bound(shared_mesh);
    // A narrow band is sampled sparsely (issue 35: only the blocks within W of a triangle; its
    // densified field is the dense band's byte for byte) and cached as the sparse file.
    // Over the ranks of a distributed run the lattice's slabs are sampled densely, as before.
    const double band_width = reach_ == SamplerReach::ThisProcess || !distributed_active() ? options_.band_width : 0.0;
    std::optional<SparseBandField> band;
    log << "  " << what << ": sampling " << (band_width > 0 ? "the sparse band " : "") << "with " << sampler.name()
        << " ..." << std::endl;
    try {
        if (band_width > 0) {
            band = sampler.sample_band_sparse(lattice, band_width);
            out.field = band->densify();
        } else {
            out.field = sampler.sample(lattice);
        }
    } catch (const std::bad_alloc&) {  // a limit the memory plan could not see: name what and how much
        const MemoryNeed need = whole_lattice_sampling_need(lattice, mesh.name());
        throw std::runtime_error(out_of_memory_message(need.what + " for " + label, need.host_bytes));
    }
    char line[160];
    std::snprintf(line, sizeof line, "  %s: sampled in %.2f s (%.3g pairs/s)", what.c_str(), out.field.timings.total,
                  out.field.timings.pairs_per_second());
    log << line;
    if (cache_) {
        out.field.mesh = describe_prepared_mesh(mesh);
        if (band) band->mesh = out.field.mesh;
        const bool stored = band ? cache_->store_band(key, *band) : cache_->store(key, out.field);
        log << (stored ? "; cached as " : "; already cached as ") << out.cache_key.substr(0, 12);
    }
    log << "\n";
    return out;
}

}  // namespace sdf
