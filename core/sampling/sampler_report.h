/// @file sampler_report.h
/// @brief How a field was sampled, as a type: SampledField::sampler. Every sampler fills one
/// (sampler_results.h: sampler_report), every path that cuts a lattice into parts (the
/// streamed slabs of sdf-sample, the ranks of an MPI run) joins the parts' reports with the
/// one `merge`, and the field header and the manifest write it with the one `to_json`.
///
/// The counters are typed, since parts add up: points computed, the narrow band's counts,
/// the certified search's counts. What one backend or path adds beside them (threads,
/// device, launch plan, BVH statistics, the sign mode, streaming, distributed) stays a JSON
/// object, `details`: per-part diagnostics that merge keeps from the first part.
///
/// JSON (harness/schema/run_schema.json, "field_sampler"): the details' keys, plus
///   "backend", "method", "kernel", "precision", "points_computed",
///   "band": {"width", "points_in_band", "points_outside", "how"
///            [, "probes", "bricks_skipped", "points_skipped"]},
///   "search_certificate": {"certified"[, "note"]
///            [, "points", "reranked_in_double", "full_double_search", "reranked_fraction"]},
///   "winding_sign": {"points", "surface", "fast", "refined", "direct", "ties"}
/// An empty report (a field made from arrays, a default SampledField) is JSON null.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace sdf {

/// The narrow band of a sampling (SamplerOptions::band_width > 0; core/sampling/narrow_band.h).
struct BandReport {
    double width = 0;
    int64_t points_in_band = 0, points_outside = 0;
    std::string how;  ///< "post-processed", "bricks skipped by the distance bound", ...
    /// The CPU BVH's brick skip counts its work: bricks probed, bricks and points skipped.
    bool counts_skips = false;
    int64_t probes = 0, bricks_skipped = 0, points_skipped = 0;
};

/// The certified float search (kernels/distance/search_certificate.h; certified_search.h).
struct CertificateReport {
    bool certified = true;  ///< the triangle is the double search's
    std::string note;       ///< why there are no counts: a double search, an uncertified one
    /// A certified float search counts its points: searched, re-ranked in double (several
    /// candidates), sent to the full double search.
    bool counted = false;
    int64_t points = 0, reranked_in_double = 0, full_double_search = 0;
};

/// The certified winding sign (kernels/winding/certified_winding.h): points signed by the
/// winding number, by how their side was decided: by the closest triangle's side
/// (surface_side.h: after a walk, or from the sole nearest triangle alone), by the fast
/// evaluation's bound, by a stricter opening rule, by the direct sum, or a tie (outside).
struct WindingSignReport {
    int64_t fast = 0, refined = 0, direct = 0, ties = 0, surface = 0, nearest = 0;
    int64_t points() const { return fast + refined + direct + ties + surface + nearest; }
};

struct SamplerReport {
    std::string backend, method, kernel, precision;  ///< empty: not made by a sampler
    int64_t points_computed = 0;
    std::optional<BandReport> band;
    std::optional<CertificateReport> search_certificate;
    std::optional<WindingSignReport> winding_sign;  ///< in winding sign mode
    nlohmann::json details = nlohmann::json::object();  ///< every other key (see the file's comment)

    bool empty() const { return backend.empty() && !band && !search_certificate && !winding_sign && details.empty(); }

    /// Adds the report of another part of the same lattice (a slab, a rank's slab), sampled
    /// with the same options: the counters are summed (points computed, the band's counts,
    /// the certificate's counts); the identity and the details are the first non-empty
    /// part's. Merging every part's report, in any order, gives the whole lattice's counters
    /// of one sampling.
    void merge(const SamplerReport& part);
};

void to_json(nlohmann::json& j, const SamplerReport& r);
/// Reads what to_json wrote (field headers, the MPI wire); a known key of the wrong type
/// throws std::runtime_error naming it ("sampler.band.points_in_band: expected an integer").
void from_json(const nlohmann::json& j, SamplerReport& r);

}  // namespace sdf
