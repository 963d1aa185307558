#include "core/sampling/sampler_report.h"

#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace sdf {

namespace {

void merge_band(BandReport& into, const BandReport& part) {
    into.points_in_band += part.points_in_band;
    into.points_outside += part.points_outside;
    into.counts_skips = into.counts_skips || part.counts_skips;
    into.probes += part.probes;
    into.bricks_skipped += part.bricks_skipped;
    into.points_skipped += part.points_skipped;
}

void merge_certificate(CertificateReport& into, const CertificateReport& part) {
    if (!into.counted || !part.counted) return;
    into.points += part.points;
    into.reranked_in_double += part.reranked_in_double;
    into.full_double_search += part.full_double_search;
}

nlohmann::json winding_sign_to_json(const WindingSignReport& w) {
    return {{"points", w.points()}, {"nearest", w.nearest}, {"surface", w.surface}, {"fast", w.fast},
            {"refined", w.refined},  {"direct", w.direct},   {"ties", w.ties}};
}

nlohmann::json band_to_json(const BandReport& b) {
    nlohmann::json j = {{"width", b.width}, {"points_in_band", b.points_in_band}, {"points_outside", b.points_outside}, {"how", b.how}};
    if (b.counts_skips) {
        j["probes"] = b.probes;
        j["bricks_skipped"] = b.bricks_skipped;
        j["points_skipped"] = b.points_skipped;
    }
    return j;
}

nlohmann::json certificate_to_json(const CertificateReport& c) {
    nlohmann::json j = {{"certified", c.certified}};
    if (!c.note.empty()) j["note"] = c.note;
    if (c.counted) {
        j["points"] = c.points;
        j["reranked_in_double"] = c.reranked_in_double;
        j["full_double_search"] = c.full_double_search;
        j["reranked_fraction"] = c.points > 0 ? double(c.reranked_in_double) / double(c.points) : 0.0;
    }
    return j;
}

/// Reads the typed keys of one JSON object, naming the key of a wrong type.
class Keys {
public:
    Keys(const nlohmann::json& j, std::string path) : j_(j), path_(std::move(path)) {
        if (!j_.is_object()) throw std::runtime_error(path_ + ": expected an object, got " + j_.dump());
    }
    bool has(const char* key) const { return j_.contains(key); }
    int64_t integer(const char* key) const {
        const nlohmann::json& v = at(key);
        if (!v.is_number_integer()) fail(key, "an integer", v);
        return v.get<int64_t>();
    }
    double number(const char* key) const {
        const nlohmann::json& v = at(key);
        if (!v.is_number()) fail(key, "a number", v);
        return v.get<double>();
    }
    std::string text(const char* key) const {
        const nlohmann::json& v = at(key);
        if (!v.is_string()) fail(key, "a string", v);
        return v.get<std::string>();
    }
    bool flag(const char* key) const {
        const nlohmann::json& v = at(key);
        if (!v.is_boolean()) fail(key, "true or false", v);
        return v.get<bool>();
    }
    const nlohmann::json& at(const char* key) const {
        if (!j_.contains(key)) throw std::runtime_error(path_ + "." + key + ": missing");
        return j_.at(key);
    }
    const std::string& path() const { return path_; }

private:
    [[noreturn]] void fail(const char* key, const char* expected, const nlohmann::json& got) const {
        throw std::runtime_error(path_ + "." + key + ": expected " + expected + ", got " + got.dump());
    }
    const nlohmann::json& j_;
    std::string path_;
};

BandReport band_from_json(const nlohmann::json& j) {
    const Keys k(j, "sampler.band");
    BandReport b;
    b.width = k.number("width");
    b.points_in_band = k.integer("points_in_band");
    b.points_outside = k.integer("points_outside");
    b.how = k.text("how");
    b.counts_skips = k.has("probes");
    if (b.counts_skips) {
        b.probes = k.integer("probes");
        b.bricks_skipped = k.integer("bricks_skipped");
        b.points_skipped = k.integer("points_skipped");
    }
    return b;
}

CertificateReport certificate_from_json(const nlohmann::json& j) {
    const Keys k(j, "sampler.search_certificate");
    CertificateReport c;
    c.certified = k.flag("certified");
    if (k.has("note")) c.note = k.text("note");
    c.counted = k.has("points");
    if (c.counted) {
        c.points = k.integer("points");
        c.reranked_in_double = k.integer("reranked_in_double");
        c.full_double_search = k.integer("full_double_search");
    }
    return c;
}

WindingSignReport winding_sign_from_json(const nlohmann::json& j) {
    const Keys k(j, "sampler.winding_sign");
    WindingSignReport w;
    w.fast = k.integer("fast");
    w.refined = k.integer("refined");
    w.direct = k.integer("direct");
    w.ties = k.integer("ties");
    w.surface = k.has("surface") ? k.integer("surface") : 0;  // fields sampled before the surface stage
    w.nearest = k.has("nearest") ? k.integer("nearest") : 0;  // ... and before the nearest triangles'
    int64_t total = 0;  // the counts' sum, which must not overflow (points() adds them)
    for (const auto& [name, count] : {std::pair<const char*, int64_t>{"nearest", w.nearest}, {"surface", w.surface}, {"fast", w.fast},
                                      {"refined", w.refined}, {"direct", w.direct}, {"ties", w.ties}}) {
        if (count < 0)
            throw std::runtime_error("sampler.winding_sign." + std::string(name) + ": expected a count >= 0, got " +
                                     std::to_string(count));
        if (count > std::numeric_limits<int64_t>::max() - total)
            throw std::runtime_error("sampler.winding_sign." + std::string(name) + ": expected counts whose sum fits in 64 bits, got " +
                                     std::to_string(count) + " after " + std::to_string(total));
        total += count;
    }
    if (k.integer("points") != w.points())
        throw std::runtime_error("sampler.winding_sign.points: expected nearest + surface + fast + refined + direct + ties = " +
                                 std::to_string(w.points()) + ", got " + j.at("points").dump());
    return w;
}

}  // namespace

void SamplerReport::merge(const SamplerReport& part) {
    if (part.empty()) return;
    if (empty()) {
        *this = part;
        return;
    }
    points_computed += part.points_computed;
    if (band && part.band) merge_band(*band, *part.band);
    else if (part.band) band = part.band;
    if (search_certificate && part.search_certificate) merge_certificate(*search_certificate, *part.search_certificate);
    else if (part.search_certificate) search_certificate = part.search_certificate;
    if (winding_sign && part.winding_sign) {
        winding_sign->fast += part.winding_sign->fast;
        winding_sign->refined += part.winding_sign->refined;
        winding_sign->direct += part.winding_sign->direct;
        winding_sign->ties += part.winding_sign->ties;
        winding_sign->surface += part.winding_sign->surface;
        winding_sign->nearest += part.winding_sign->nearest;
    } else if (part.winding_sign) {
        winding_sign = part.winding_sign;
    }
    if (backend.empty()) {
        backend = part.backend;
        method = part.method;
        kernel = part.kernel;
        precision = part.precision;
    }
}

void to_json(nlohmann::json& j, const SamplerReport& r) {
    if (r.empty()) {
        j = nullptr;
        return;
    }
    j = r.details;
    if (!r.backend.empty()) {
        j["backend"] = r.backend;
        j["method"] = r.method;
        j["kernel"] = r.kernel;
        j["precision"] = r.precision;
        j["points_computed"] = r.points_computed;
    }
    if (r.band) j["band"] = band_to_json(*r.band);
    if (r.search_certificate) j["search_certificate"] = certificate_to_json(*r.search_certificate);
    if (r.winding_sign) j["winding_sign"] = winding_sign_to_json(*r.winding_sign);
}

void from_json(const nlohmann::json& j, SamplerReport& r) {
    r = SamplerReport();
    if (j.is_null()) return;
    const Keys k(j, "sampler");
    r.details = j;
    if (k.has("backend")) {
        r.backend = k.text("backend");
        r.method = k.text("method");
        r.kernel = k.text("kernel");
        r.precision = k.text("precision");
        r.points_computed = k.integer("points_computed");
    }
    if (k.has("band")) r.band = band_from_json(j.at("band"));
    if (k.has("search_certificate")) r.search_certificate = certificate_from_json(j.at("search_certificate"));
    if (k.has("winding_sign")) r.winding_sign = winding_sign_from_json(j.at("winding_sign"));
    for (const char* key : {"backend", "method", "kernel", "precision", "points_computed", "band", "search_certificate",
                            "winding_sign"})
        r.details.erase(key);
}

}  // namespace sdf
