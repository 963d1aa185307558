/// @file field_cache.h
/// @brief Sampled fields in the content-addressed cache (content_cache.h), reused across
/// runs and experiments.
///
/// The key is what determines the field: the mesh's SHA-256 (file bytes, or the generated
/// geometry), the lattice (type, exact origin and spacing, resolution), the sampler's
/// identity (method, kernel as configured - "" means the backend's default -, precision,
/// BCC strategy for BCC lattices) and kFieldCodeVersion. Backend and thread count are not
/// part of it: every backend computes the same field up to float ties; the entry records
/// which one filled it. Fields are stored as float64, so a cached field equals the fresh one.
#pragma once

#include <optional>
#include <string>

#include "core/sampling/sampler.h"
#include "harness/cache/content_cache.h"

namespace sdf {

/// Bump when sampling semantics change (what a sampler computes for a given key), so old
/// entries are no longer found.
constexpr int kFieldCodeVersion = 1;

nlohmann::json field_cache_key(const std::string& mesh_sha256, const Lattice& lattice, const SamplerOptions& sampler);

class FieldCache {
public:
    explicit FieldCache(std::string root) : store_(std::move(root)) {}
    const std::string& root() const { return store_.root(); }

    /// Whether an entry exists (not verified: for plans; load() verifies).
    bool contains(const nlohmann::json& key) const { return store_.has_entry("fields", key); }
    std::string entry_path(const nlohmann::json& key) const { return store_.entry_path("fields", key); }
    /// The cached field (timings as measured when it was filled), or nullopt: also when the
    /// entry fails verification (ContentCache::find moves it aside with a warning), so the
    /// caller samples it again.
    std::optional<SampledField> load(const nlohmann::json& key) const;
    /// Stores `field` unless the key is present; returns whether it was stored.
    bool store(const nlohmann::json& key, const SampledField& field) const;

private:
    ContentCache store_;
};

}  // namespace sdf
