#include "harness/cache/field_cache.h"

#include <cstdio>
#include <filesystem>

#include "core/sampling/sampler_sign.h"
#include "harness/config/json_reader.h"
#include "harness/config/sampler_spec.h"
#include "harness/io/field_file.h"
#include "harness/io/sparse_field_file.h"
#include "harness/provenance/provenance.h"

namespace sdf {
namespace fs = std::filesystem;

namespace {

/// Exact text of a double ("%a"), so keys never depend on decimal rounding.
std::string exact(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%a", v);
    return buf;
}

}  // namespace

nlohmann::json field_cache_key(const std::string& mesh_sha256, const Lattice& l, const SamplerOptions& o) {
    nlohmann::json key = {{"what", "sampled_field"},
            {"code_version", kFieldCodeVersion},
            {"mesh_sha256", mesh_sha256},
            {"lattice", {{"type", lattice_type_name(l.type)},
                         {"origin", {exact(l.origin.x), exact(l.origin.y), exact(l.origin.z)}},
                         {"spacing", exact(l.spacing)},
                         {"resolution", {l.resolution.x, l.resolution.y, l.resolution.z}}}},
            // Every option of role Result, from the codec's table (the sign as requested: auto
            // resolves from the mesh, which mesh_sha256 fixes).
            {"sampler", sampler_result_identity(o, l.type)}};
    // The measurement switch's fields (SamplerSign::winding_options) never pass for certified ones.
    if (!SamplerSign::winding_options().certify) key["winding_sign"] = "uncertified (SDF_WINDING_UNCERTIFIED=1)";
    return key;
}

std::optional<SampledField> FieldCache::load(const nlohmann::json& key) const {
    const std::optional<std::string> found = store_.find("fields", key);
    if (!found) return std::nullopt;
    const std::string dir = *found;
    try {
        const std::string header = dir + "/field.json";
        SampledField field = is_sparse_field_file(header) ? read_sparse_field(header).densify() : read_field(header);
        const nlohmann::json info = read_json_file(dir + "/entry.json").at("info");
        const nlohmann::json& t = info.at("timings_seconds");
        field.timings.total = t.at("total");
        field.timings.kernel = t.at("kernel");
        field.timings.upload = t.at("upload");
        field.timings.download = t.at("download");
        field.timings.point_triangle_pairs = info.at("point_triangle_pairs");
        field.precision = key.at("sampler").at("precision") == "double" ? Precision::Double : Precision::Float;
        return field;
    } catch (const std::exception& e) {
        throw std::runtime_error("field cache entry " + dir + " is damaged (" + e.what() +
                                 "); remove that directory or run with --no-cache");
    }
}

namespace {

nlohmann::json entry_info(const SamplerReport& sampler, const SamplingTimings& timings) {
    return {{"filled_by", sampler},
            {"host_cpu", cpu_model()},
            {"timings_seconds", {{"total", timings.total},
                                 {"kernel", timings.kernel},
                                 {"upload", timings.upload},
                                 {"download", timings.download}}},
            {"point_triangle_pairs", timings.point_triangle_pairs},
            {"git_commit", git_state().commit}};
}

}  // namespace

bool FieldCache::store_band(const nlohmann::json& key, const SparseBandField& band) const {
    return store_.store("fields", key, entry_info(band.sampler, band.timings), [&](const std::string& dir) {
        SparseFieldWriteOptions o;
        o.dtype = FieldDtype::Float64;
        write_sparse_field(dir + "/field.json", band, o);
    });
}

bool FieldCache::store(const nlohmann::json& key, const SampledField& field) const {
    const nlohmann::json info = {{"filled_by", field.sampler},
                                 {"host_cpu", cpu_model()},
                                 {"timings_seconds", {{"total", field.timings.total},
                                                      {"kernel", field.timings.kernel},
                                                      {"upload", field.timings.upload},
                                                      {"download", field.timings.download}}},
                                 {"point_triangle_pairs", field.timings.point_triangle_pairs},
                                 {"git_commit", git_state().commit}};
    return store_.store("fields", key, info, [&](const std::string& dir) {
        FieldWriteOptions o;
        o.dtype = FieldDtype::Float64;
        write_field(dir + "/field.json", field, o);
    });
}

}  // namespace sdf
