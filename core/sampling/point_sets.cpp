#include "core/sampling/point_sets.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/quoted_alternatives.h"

namespace sdf {
namespace {

/// SplitMix64 (Steele, Lea & Flood, "Fast Splittable Pseudorandom Number Generators", OOPSLA 2014).
struct SplitMix64 {
    uint64_t state;
    uint64_t next() {
        uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    /// Uniform in [0, 1): the top 53 bits.
    double uniform() { return double(next() >> 11) * 0x1.0p-53; }
    /// Standard normal (Box-Muller; the second value is dropped to keep the stream simple).
    double normal() {
        const double u1 = 1.0 - uniform();  // (0, 1]
        const double u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
    }
};

constexpr struct {
    PointSetKind kind;
    const char* name;
} kPointSetKinds[] = {{PointSetKind::UniformBox, "uniform_box"}, {PointSetKind::GaussianSurface, "gaussian_surface"}};

}  // namespace

const char* point_set_kind_name(PointSetKind kind) {
    for (const auto& k : kPointSetKinds)
        if (k.kind == kind) return k.name;
    return "?";
}

PointSetKind point_set_kind_from_name(const std::string& name) {
    std::vector<std::string> names;
    for (const auto& k : kPointSetKinds) {
        if (name == k.name) return k.kind;
        names.emplace_back(k.name);
    }
    throw std::invalid_argument("unknown point set kind \"" + name + "\"; expected one of " + quoted_alternatives(names));
}

std::string point_set_label(const PointSetSpec& spec) {
    std::string label = point_set_kind_name(spec.kind);
    if (spec.kind == PointSetKind::GaussianSurface) {
        char sigma[32];
        std::snprintf(sigma, sizeof sigma, "%g", spec.sigma);
        label += std::string("(sigma=") + sigma + ")";
    }
    return label + "/" + std::to_string(spec.count);
}

std::vector<Vec3d> make_point_set(const PreparedMesh& mesh, const PointSetSpec& spec) {
    if (spec.count < 0) throw std::invalid_argument("point set: expected a non-negative count, got " + std::to_string(spec.count));
    std::vector<Vec3d> points(size_t(spec.count));
    SplitMix64 rng{spec.seed};
    const Bounds3 b = mesh.bounds();
    if (spec.kind == PointSetKind::UniformBox) {
        const Vec3d e = b.extent();
        const double pad = spec.margin * std::max({e.x, e.y, e.z});
        const Vec3d lo = b.min - Vec3d{pad, pad, pad}, size = e + Vec3d{2 * pad, 2 * pad, 2 * pad};
        for (Vec3d& p : points) {
            const double x = rng.uniform(), y = rng.uniform(), z = rng.uniform();
            p = lo + Vec3d{x * size.x, y * size.y, z * size.z};
        }
        return points;
    }
    // Area-weighted triangle choice by binary search in the cumulative areas.
    const auto& v = mesh.vertices();
    const auto& t = mesh.triangles();
    if (t.empty()) throw std::invalid_argument("point set gaussian_surface: the mesh has no triangles");
    std::vector<double> cumulative(t.size());
    double total = 0;
    for (size_t i = 0; i < t.size(); ++i) {
        const Vec3d a = v[size_t(t[i].x)], bb = v[size_t(t[i].y)], c = v[size_t(t[i].z)];
        total += 0.5 * length(cross(bb - a, c - a));
        cumulative[i] = total;
    }
    const double sigma = spec.sigma * b.diagonal();
    for (Vec3d& p : points) {
        const double pick = rng.uniform() * total;
        const size_t i = std::min(size_t(std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin()), t.size() - 1);
        double s = rng.uniform(), r = rng.uniform();
        if (s + r > 1) {  // fold the square onto the triangle: uniform barycentrics
            s = 1 - s;
            r = 1 - r;
        }
        const Vec3d a = v[size_t(t[i].x)], bb = v[size_t(t[i].y)], c = v[size_t(t[i].z)];
        const double ox = rng.normal(), oy = rng.normal(), oz = rng.normal();
        p = a + (bb - a) * s + (c - a) * r + Vec3d{ox, oy, oz} * sigma;
    }
    return points;
}

}  // namespace sdf
