#include "core/sampling/adversarial_cases.h"

#include <algorithm>
#include <cmath>

#include "core/mesh/shapes/procedural_shapes.h"

namespace sdf {
namespace {

/// SplitMix64 (Steele, Lea & Flood 2014), as point_sets.cpp uses it.
struct Random {
    uint64_t state;
    uint64_t next() {
        uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }
    double uniform() { return double(next() >> 11) * 0x1p-53; }            ///< [0, 1)
    double between(double a, double b) { return a + (b - a) * uniform(); }
    double log_between(double a, double b) { return std::exp(between(std::log(a), std::log(b))); }
    Vec3d direction() {
        for (;;) {
            const Vec3d v(between(-1, 1), between(-1, 1), between(-1, 1));
            const double l = length(v);
            if (l > 0.1 && l <= 1.0) return v * (1.0 / l);
        }
    }
};

TriangleMesh translated(TriangleMesh m, Vec3d offset, const std::string& name) {
    for (Vec3d& v : m.vertices) v = v + offset;
    m.name = name;
    m.source = "adversarial:" + name;
    return m;
}

TriangleMesh appended(TriangleMesh a, const TriangleMesh& b, const std::string& name) {
    const int base = int(a.vertices.size());
    a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
    for (const Int3& t : b.triangles) a.triangles.push_back({t.x + base, t.y + base, t.z + base});
    a.name = name;
    a.source = "adversarial:" + name;
    return a;
}

/// A unit cube, each face two triangles split by a diagonal.
TriangleMesh cube() {
    TriangleMesh m;
    for (int i = 0; i < 8; ++i) m.vertices.push_back({i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5});
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        m.triangles.push_back({q[0], q[1], q[2]});
        m.triangles.push_back({q[0], q[2], q[3]});
    }
    m.name = "cube";
    m.source = "adversarial:cube";
    return m;
}

/// A strip of slivers: triangles between two lines 1e-3 .. 3e-2 apart over a unit length,
/// angles near the sliver threshold (kSliverSin2) on both sides of it.
TriangleMesh slivers() {
    TriangleMesh m;
    const int n = 40;
    for (int i = 0; i <= n; ++i) {
        const double x = double(i) / n, w = 1e-3 * std::pow(30.0, double(i % 7) / 6.0);
        m.vertices.push_back({x, 0.0, 0.01 * std::sin(7.0 * x)});
        m.vertices.push_back({x + 0.5 / n, w, 0.01 * std::sin(7.0 * x + 0.3)});
    }
    for (int i = 0; i < n; ++i) {
        m.triangles.push_back({2 * i, 2 * i + 2, 2 * i + 1});
        m.triangles.push_back({2 * i + 1, 2 * i + 2, 2 * i + 3});
    }
    m.name = "slivers";
    m.source = "adversarial:slivers";
    return m;
}

/// One group of make_sliver_zoo(): the sliver, then its neighbours folded 0.05 L below its plane.
struct SliverGroup {
    Vec3d sliver[3];
};

SliverGroup add_sliver_group(TriangleMesh& m, Vec3d o, double length, double degrees, bool cap) {
    const double theta = degrees * (3.14159265358979323846 / 180.0);
    auto at = [&](double x, double y, double z) {
        m.vertices.push_back(o + Vec3d(x, y, z) * length);
        return int(m.vertices.size()) - 1;
    };
    SliverGroup g;
    if (!cap) {  // a needle: angle theta at the apex A; the neighbours share its three edges
        const int a = at(0, 0, 0), b = at(std::cos(0.5 * theta), std::sin(0.5 * theta), 0),
                  c = at(std::cos(0.5 * theta), -std::sin(0.5 * theta), 0);
        const int d = at(0.3, 0.2, -0.05), e = at(0.3, -0.2, -0.05), f = at(1.2, 0, -0.05);
        m.triangles.push_back({a, c, b});
        m.triangles.push_back({a, b, d});
        m.triangles.push_back({a, e, c});
        m.triangles.push_back({c, f, b});
    } else {  // a cap: angles theta at A and about 0.59 theta at B, C near their edge
        const int a = at(0, 0, 0), b = at(1, 0, 0), c = at(0.37, 0.37 * std::tan(theta), 0);
        const int gv = at(0.5, -0.3, -0.05), h = at(0.5, 0.3, -0.05);
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, gv, b});
        m.triangles.push_back({a, c, h});
        m.triangles.push_back({c, b, h});
    }
    const Int3 t = m.triangles[m.triangles.size() - 4];
    g.sliver[0] = m.vertices[size_t(t.x)];
    g.sliver[1] = m.vertices[size_t(t.y)];
    g.sliver[2] = m.vertices[size_t(t.z)];
    return g;
}

/// Points around a sliver of length L: on it, 1e-9 L .. 0.3 L above and below it, just
/// beside its edges in its plane, and around its vertices.
void add_sliver_points(std::vector<Vec3d>& points, const SliverGroup& g, double length, Random& rng, int count) {
    const Vec3d a = g.sliver[0], b = g.sliver[1], c = g.sliver[2];
    const Vec3d n = normalize_or_zero(cross(b - a, c - a));
    for (int i = 0; i < count; ++i) {
        const double u = rng.uniform(), v = rng.uniform() * (1.0 - u), kind = rng.uniform();
        const Vec3d on = a + (b - a) * u + (c - a) * v;
        const double height = rng.uniform() < 0.2 ? 0.0 : (rng.uniform() < 0.5 ? -1 : 1) * length * rng.log_between(1e-9, 0.3);
        if (kind < 0.5) {
            points.push_back(on + n * height);
        } else if (kind < 0.8) {  // beside an edge, in the plane or above it
            const Vec3d p = rng.uniform() < 0.5 ? a + (b - a) * u : (rng.uniform() < 0.5 ? a + (c - a) * u : b + (c - b) * u);
            const Vec3d side = normalize_or_zero(cross(n, rng.direction())) * (length * rng.log_between(1e-12, 1e-2));
            points.push_back(p + side + n * (rng.uniform() < 0.5 ? 0.0 : height));
        } else {  // around a vertex
            const Vec3d p = kind < 0.87 ? a : (kind < 0.94 ? b : c);
            points.push_back(p + rng.direction() * (length * rng.log_between(1e-10, 0.5)));
        }
    }
}

}  // namespace

AdversarialCase make_sliver_zoo(double length, uint64_t seed, int points_per_sliver) {
    AdversarialCase z;
    TriangleMesh& m = z.mesh;
    Random rng{seed};
    int group = 0;
    for (const bool cap : {false, true}) {
        for (const double degrees : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8}) {
            const Vec3d o(3.0 * length * group++, 0.0, 0.0);
            add_sliver_points(z.points, add_sliver_group(m, o, length, degrees, cap), length, rng, points_per_sliver);
        }
    }
    m.name = length >= 1.0 ? "sliver_zoo_long" : "sliver_zoo_short";
    m.source = "adversarial:" + m.name;
    return z;
}

TriangleMesh make_fan_plate(int per_side, double half, Vec3d center) {
    TriangleMesh m;
    const double thick = 0.1 * half;
    const int ring = 4 * per_side;
    // Boundary ring, counter-clockwise seen from +z: per_side collinear vertices a side.
    auto boundary = [&](int i) {
        const int side = i / per_side;
        const double f = -1.0 + 2.0 * double(i % per_side) / per_side;
        switch (side) {
        case 0: return Vec3d(f * half, -half, 0);
        case 1: return Vec3d(half, f * half, 0);
        case 2: return Vec3d(-f * half, half, 0);
        default: return Vec3d(-half, -f * half, 0);
        }
    };
    for (int layer = 0; layer < 2; ++layer)
        for (int i = 0; i < ring; ++i) m.vertices.push_back(center + boundary(i) + Vec3d(0, 0, layer ? thick : -thick));
    // Fan centres: off-centre, as CAD exporters pick one polygon vertex's neighbourhood.
    const int top = int(m.vertices.size());
    m.vertices.push_back(center + Vec3d(0.31 * half, -0.17 * half, thick));
    const int bottom = top + 1;
    m.vertices.push_back(center + Vec3d(-0.23 * half, 0.41 * half, -thick));
    for (int i = 0; i < ring; ++i) {
        const int j = (i + 1) % ring;
        m.triangles.push_back({top, ring + i, ring + j});  // top fan, normal +z
        m.triangles.push_back({bottom, j, i});             // bottom fan, normal -z
        m.triangles.push_back({i, j, ring + j});           // side strip
        m.triangles.push_back({i, ring + j, ring + i});
    }
    m.name = "fan_plate";
    m.source = "adversarial:fan_plate";
    return m;
}

std::vector<Vec3d> adversarial_points(const TriangleMesh& mesh, uint64_t seed, int count) {
    Random rng{seed};
    const Bounds3 box = triangle_bounds(mesh.vertices, mesh.triangles);
    const double scale = box.diagonal();
    std::vector<Vec3d> points;
    points.reserve(size_t(count));
    while (int(points.size()) < count) {
        const Int3 t = mesh.triangles[size_t(rng.next() % mesh.triangles.size())];
        const Vec3d a = mesh.vertices[size_t(t.x)], b = mesh.vertices[size_t(t.y)], c = mesh.vertices[size_t(t.z)];
        const Vec3d n = normalize_or_zero(cross(b - a, c - a));
        const double u = rng.uniform(), pick = rng.uniform();
        Vec3d base;
        if (pick < 0.45) base = a + (b - a) * u;                        // on an edge (a cube's diagonal among them)
        else if (pick < 0.7) base = pick < 0.6 ? a : b;                 // at a vertex
        else {                                                          // inside the face
            const double v = rng.uniform() * (1.0 - u);
            base = a + (b - a) * u + (c - a) * v;
        }
        const bool far = rng.uniform() < 0.1;
        const double height = scale * (far ? rng.log_between(1e-2, 1.0) : rng.log_between(1e-5, 1e-2));
        const double side = rng.uniform() < 0.5 ? -1.0 : 1.0;
        const Vec3d lateral = rng.direction() * (scale * rng.log_between(1e-8, 1e-3));
        points.push_back(base + n * (side * height) + lateral);
    }
    return points;
}

std::vector<AdversarialCase> adversarial_cases(uint64_t seed, int points_per_case) {
    std::vector<TriangleMesh> meshes;
    meshes.push_back(cube());
    meshes.push_back(make_fan_plate(24, 1.0));
    meshes.push_back(slivers());
    for (double offset : {1e3, 1e5}) {
        const std::string tag = offset < 1e4 ? "1e3" : "1e5";
        meshes.push_back(translated(cube(), {offset, -0.5 * offset, 0.25 * offset}, "cube_at_" + tag));
        meshes.push_back(translated(make_fan_plate(24, 1.0), {offset, offset, -offset}, "fan_plate_at_" + tag));
    }
    // Nested and overlapping parts at tiny gaps: a sphere 5e-4 above the box's top face, a
    // box nested inside, and a second box overlapping the first.
    TriangleMesh parts = translated(make_box({0.5, 0.5, 0.5}), {}, "box");
    parts = appended(parts, make_icosphere(3, 0.3, {0.0, 0.0, 0.5 + 0.3 + 5e-4}), "parts");
    parts = appended(parts, make_box({0.5 - 1e-4, 0.3, 0.3}), "parts");
    parts = appended(parts, make_box({0.3, 0.3, 0.3}, {0.7, 0.1, 0.0}), "box_sphere_nested_overlapping");
    meshes.push_back(parts);

    std::vector<AdversarialCase> cases;
    uint64_t s = seed;
    for (TriangleMesh& m : meshes) {
        AdversarialCase c;
        c.points = adversarial_points(m, s++, points_per_case);
        if (m.name == "box_sphere_nested_overlapping") {
            Random rng{s * 31};  // the gap between the box and the sphere
            for (int i = 0; i < points_per_case / 4; ++i)
                c.points[size_t(i)] = {rng.between(-0.05, 0.05), rng.between(-0.05, 0.05), 0.5 + rng.between(0.0, 5e-4)};
        }
        c.mesh = std::move(m);
        cases.push_back(std::move(c));
    }
    // Slivers of every size (1e-2 .. 1e-8 degrees, needles and caps, 100 and 1e-3 long) beside
    // neighbours, with points on, around and just beside them.
    for (const double length : {100.0, 1e-3})
        cases.push_back(make_sliver_zoo(length, s++, std::max(1, points_per_case / 14)));
    return cases;
}

}  // namespace sdf
