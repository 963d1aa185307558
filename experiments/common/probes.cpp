#include "experiments/common/probes.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>

#include "harness/cache/content_cache.h"
#include "harness/config/sampler_spec.h"
#include "harness/io/atomic_file.h"

namespace sdf {
namespace {

/// Uniform double in [0, 1) from 53 random bits: the same on every platform.
double unit(std::mt19937_64& rng) { return double(rng() >> 11) * (1.0 / 9007199254740992.0); }

std::string exact(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%a", v);
    return buf;
}

nlohmann::json cache_key(const PreparedMesh& mesh, const DomainBox<double>& box, double band_width, const ProbeSpec& spec,
                         const SamplerOptions& o) {
    return {{"what", "probes"},
            {"code_version", kProbeCodeVersion},
            {"mesh_sha256", mesh.content_sha256()},
            {"box", {exact(box.lo.x), exact(box.lo.y), exact(box.lo.z), exact(box.hi.x), exact(box.hi.y), exact(box.hi.z)}},
            {"band_width", exact(band_width)},
            {"domain_probes", spec.domain_probes},
            {"band_probes", spec.band_probes},
            {"seed", spec.seed},
            // The options that decide exact values, from the codec (the sign included): the
            // same rule as the field cache's key. Probes are points, not a lattice.
            {"sampler", sampler_result_identity(o, LatticeType::CC)}};
}

std::vector<Vec3d> place_probes(const PreparedMesh& mesh, const DomainBox<double>& box, double w, const ProbeSpec& spec) {
    std::mt19937_64 rng(spec.seed);
    std::vector<Vec3d> pts;
    pts.reserve(size_t(spec.domain_probes + spec.band_probes));
    const Vec3d size = box.hi - box.lo;
    for (int64_t i = 0; i < spec.domain_probes; ++i)
        pts.push_back(box.lo + Vec3d(unit(rng) * size.x, unit(rng) * size.y, unit(rng) * size.z));
    // Area-weighted triangle choice.
    std::vector<double> cdf(mesh.triangles().size());
    double total = 0;
    for (size_t t = 0; t < mesh.triangles().size(); ++t) {
        const Int3 v = mesh.triangles()[t];
        total += 0.5 * length(cross(mesh.vertices()[size_t(v.y)] - mesh.vertices()[size_t(v.x)],
                                    mesh.vertices()[size_t(v.z)] - mesh.vertices()[size_t(v.x)]));
        cdf[t] = total;
    }
    auto inside = [&](const Vec3d& p) {
        return p.x >= box.lo.x && p.y >= box.lo.y && p.z >= box.lo.z && p.x <= box.hi.x && p.y <= box.hi.y && p.z <= box.hi.z;
    };
    for (int64_t i = 0, attempts = 0; i < spec.band_probes && attempts < 100 * spec.band_probes + 1000; ++attempts) {
        const size_t t = size_t(std::lower_bound(cdf.begin(), cdf.end(), unit(rng) * total) - cdf.begin());
        const Int3 v = mesh.triangles()[std::min(t, cdf.size() - 1)];
        const double r1 = std::sqrt(unit(rng)), r2 = unit(rng);
        const Vec3d on = mesh.vertices()[size_t(v.x)] * (1 - r1) + mesh.vertices()[size_t(v.y)] * (r1 * (1 - r2)) +
                         mesh.vertices()[size_t(v.z)] * (r1 * r2);
        const Vec3d p = on + mesh.face_normals()[std::min(t, cdf.size() - 1)] * ((2 * unit(rng) - 1) * w);
        if (!inside(p)) continue;
        pts.push_back(p);
        ++i;
    }
    return pts;
}

/// Stored as one float64 array: 7 numbers per probe (x y z d gx gy gz).
std::vector<double> pack(const ProbeSet& s) {
    std::vector<double> out;
    out.reserve(s.points.size() * 7);
    for (size_t i = 0; i < s.points.size(); ++i)
        for (double v : {s.points[i].x, s.points[i].y, s.points[i].z, s.distance[i], s.gradient[i].x, s.gradient[i].y,
                         s.gradient[i].z})
            out.push_back(v);
    return out;
}

ProbeSet unpack(const std::string& dir, const nlohmann::json& info, double band_width) {
    const std::string file = dir + "/probes.f64";
    std::ifstream in(file, std::ios::binary | std::ios::ate);
    const size_t n = info.at("count").get<size_t>();
    if (!in || size_t(in.tellg()) != n * 7 * sizeof(double))
        throw std::runtime_error("probe cache entry " + dir + " is damaged (" + file +
                                 " has the wrong size); remove that directory or run with --no-cache");
    std::vector<double> raw(n * 7);
    in.seekg(0);
    in.read(reinterpret_cast<char*>(raw.data()), std::streamsize(raw.size() * sizeof(double)));
    ProbeSet s;
    s.band_width = band_width;
    s.domain_count = info.at("domain_count").get<int64_t>();
    for (size_t i = 0; i < n; ++i) {
        const double* r = &raw[7 * i];
        s.points.push_back({r[0], r[1], r[2]});
        s.distance.push_back(r[3]);
        s.gradient.push_back({r[4], r[5], r[6]});
    }
    return s;
}

struct Accumulator {
    double squares = 0, abs = 0, max_abs = 0;
    int64_t n = 0;
    void add(double e) {
        squares += e * e;
        abs += std::abs(e);
        max_abs = std::max(max_abs, std::abs(e));
        ++n;
    }
    nlohmann::json json() const {
        return {{"count", n},
                {"rms", n ? std::sqrt(squares / double(n)) : 0.0},
                {"mean_abs", n ? abs / double(n) : 0.0},
                {"max_abs", max_abs}};
    }
};

double angle_degrees(const Vec3d& exact_gradient, const Vec3d& got) {
    const double c = dot(exact_gradient, got), s = length(cross(exact_gradient, got));
    if (c == 0 && s == 0) return 90.0;  // no reconstructed gradient
    return std::atan2(s, c) * (180.0 / 3.14159265358979323846);
}

}  // namespace

ProbeSet make_probes(const PreparedMesh& mesh, const DomainBox<double>& box, double band_width, const ProbeSpec& spec,
                     const std::function<const BoundSampler&()>& sampler, const SamplerOptions& o, const ContentCache* cache,
                     std::string* log_line) {
    const nlohmann::json key = cache_key(mesh, box, band_width, spec, o);
    if (cache)
        if (const auto dir = cache->find("probes", key)) {
            if (log_line) *log_line = "probes from the cache (" + ContentCache::key_hash(key).substr(0, 12) + ")";
            return unpack(*dir, cache->entry_record("probes", key).at("info"), band_width);
        }
    ProbeSet s;
    s.band_width = band_width;
    s.points = place_probes(mesh, box, band_width, spec);
    s.domain_count = spec.domain_probes;
    const BoundSampler& bound = sampler();
    const std::vector<PointSample> exact_samples = bound.query(s.points);
    for (const PointSample& q : exact_samples) {
        s.distance.push_back(q.distance);
        s.gradient.push_back(q.gradient);
    }
    if (log_line) *log_line = "probes: exact distances computed with " + bound.name();
    if (cache) {
        const std::vector<double> raw = pack(s);
        const nlohmann::json info = {{"count", s.points.size()}, {"domain_count", s.domain_count}, {"sampler", bound.name()}};
        cache->store("probes", key, info, [&](const std::string& dir) {
            write_file_atomically(dir + "/probes.f64", raw.data(), raw.size() * sizeof(double));
        });
        if (log_line) *log_line += "; cached as " + ContentCache::key_hash(key).substr(0, 12);
    }
    return s;
}

nlohmann::json probe_errors(const ProbeSet& probes, const std::vector<ReconstructedSample<double>>& got) {
    Accumulator domain, band, all;
    std::vector<double> angles;
    for (size_t i = 0; i < probes.points.size(); ++i) {
        const double e = got[i].value - probes.distance[i];
        all.add(e);
        if (int64_t(i) < probes.domain_count) domain.add(e);
        if (probes.in_band(i)) {
            band.add(e);
            angles.push_back(angle_degrees(probes.gradient[i], got[i].gradient));
        }
    }
    double mean_angle = 0, p95 = 0;
    if (!angles.empty()) {
        for (double a : angles) mean_angle += a;
        mean_angle /= double(angles.size());
        const size_t k = std::min(angles.size() - 1, size_t(std::ceil(0.95 * double(angles.size()))) - 1);
        std::nth_element(angles.begin(), angles.begin() + long(k), angles.end());
        p95 = angles[k];
    }
    nlohmann::json b = band.json();
    b["gradient_angle_mean_deg"] = mean_angle;
    b["gradient_angle_p95_deg"] = p95;
    return {{"domain", domain.json()}, {"band", b}, {"max_abs", all.max_abs}};
}

}  // namespace sdf
