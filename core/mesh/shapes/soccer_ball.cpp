// Soccer ball (thesis Fig. 5-1 A): a truncated icosahedron blown up onto the unit sphere, with
// grooves engraved along the 90 seams between its 12 pentagonal and 20 hexagonal panels.
//
// Each flat panel is triangulated on its own, as nested copies of its outline shrunk towards
// its centre ("rings"): a fan grid of `detail` + 1 rings covers the flat part and ends where
// the groove begins; one more ring lies on the groove's flank and the outline itself lies on
// the seam. Outlines share their vertices with the neighbouring panels, so the mesh is closed.
// Every vertex is then projected onto the sphere and sunk by the groove profile of its angular
// distance to the nearest seam. The panels triangulate a convex polyhedron around the origin
// and only radii change, so the surface stays star-shaped: it cannot cross itself.
//
// Counts: with n = detail + 1, T = 180 (n^2 + 4n) triangles and V = T/2 + 2 vertices;
// detail = 2 gives 3,780 triangles and 1,892 vertices (the thesis's ball has 3,516 / 1,760).
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/mesh/shapes/procedural_shapes.h"
#include "core/mesh/shapes/stitch_rings.h"

namespace sdf {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// The flank ring lies at a third of the groove's half width from the seam, where the cosine
/// profile is 3/4 deep: with the groove's edge and the seam that makes a round-bottomed groove.
constexpr double kFlankFraction = 1.0 / 3.0;

/// 60 corners on the unit sphere and 32 flat panels, each a list of corner ids in
/// counter-clockwise order seen from outside.
struct Polyhedron {
    std::vector<Vec3d> corners;
    std::vector<std::vector<int>> panels;
};

/// Cuts every corner of an icosahedron at a third of each edge: the 12 corners become
/// pentagons, the 20 faces hexagons, and all 90 edges get the same length.
Polyhedron truncated_icosahedron() {
    const TriangleMesh ico = make_icosphere(0);
    Polyhedron p;
    std::map<std::pair<int, int>, int> near;  // (a, b) -> the corner on edge ab next to a
    auto corner = [&](int a, int b) {
        auto [it, inserted] = near.emplace(std::make_pair(a, b), int(p.corners.size()));
        if (inserted) {
            const Vec3d& va = ico.vertices[size_t(a)];
            p.corners.push_back(va + (ico.vertices[size_t(b)] - va) / 3.0);
        }
        return it->second;
    };
    // A hexagon keeps the middle third of each edge of face (a, b, c); around vertex a the
    // face's edge ab is followed by its edge ac.
    std::map<std::pair<int, int>, int> next_around;
    for (const Int3& f : ico.triangles) {
        p.panels.push_back({corner(f.x, f.y), corner(f.y, f.x), corner(f.y, f.z), corner(f.z, f.y),
                            corner(f.z, f.x), corner(f.x, f.z)});
        for (int k = 0; k < 3; ++k) next_around[{f[k], f[(k + 1) % 3]}] = f[(k + 2) % 3];
    }
    // A pentagon walks around its icosahedron vertex, opposite to the hexagons' edges.
    for (int a = 0; a < int(ico.vertices.size()); ++a) {
        int b = next_around.lower_bound({a, -1})->first.second;
        std::vector<int> pentagon;
        for (int k = 0; k < 5; ++k, b = next_around.at({a, b})) pentagon.push_back(corner(a, b));
        p.panels.push_back(pentagon);
    }
    for (Vec3d& c : p.corners) c = normalize_or_zero(c);
    return p;
}

/// The n - 1 vertices inside every edge, stored from the lower corner id to the higher one.
using EdgeVertices = std::map<std::pair<int, int>, std::vector<int>>;

EdgeVertices add_edge_vertices(const Polyhedron& p, int n, std::vector<Vec3d>& vertices) {
    EdgeVertices edges;
    for (const std::vector<int>& panel : p.panels)
        for (size_t s = 0; s < panel.size(); ++s) {
            const int a = std::min(panel[s], panel[(s + 1) % panel.size()]);
            const int b = std::max(panel[s], panel[(s + 1) % panel.size()]);
            auto [it, inserted] = edges.try_emplace({a, b});
            if (!inserted) continue;
            for (int i = 1; i < n; ++i) {
                it->second.push_back(int(vertices.size()));
                const Vec3d &from = p.corners[size_t(a)], &to = p.corners[size_t(b)];
                vertices.push_back(from + (to - from) * (double(i) / n));
            }
        }
    return edges;
}

/// The panel's outline: corners (vertex id = corner id) and the shared edge vertices.
std::vector<int> outline_ring(const std::vector<int>& panel, const EdgeVertices& edges) {
    std::vector<int> ring;
    for (size_t s = 0; s < panel.size(); ++s) {
        const int a = panel[s], b = panel[(s + 1) % panel.size()];
        std::vector<int> inside = edges.at({std::min(a, b), std::max(a, b)});
        if (a > b) std::reverse(inside.begin(), inside.end());
        ring.push_back(a);
        ring.insert(ring.end(), inside.begin(), inside.end());
    }
    return ring;
}

/// The outline shrunk towards `center` by `scale`, each side split into `m` pieces.
std::vector<int> inner_ring(const std::vector<Vec3d>& outline, const Vec3d& center, double scale, int m,
                            std::vector<Vec3d>& vertices) {
    std::vector<int> ring;
    for (size_t s = 0; s < outline.size(); ++s) {
        const Vec3d& a = outline[s];
        const Vec3d& b = outline[(s + 1) % outline.size()];
        for (int i = 0; i < m; ++i) {
            ring.push_back(int(vertices.size()));
            vertices.push_back(center + (a + (b - a) * (double(i) / m) - center) * scale);
        }
    }
    return ring;
}

/// The scale of the ring that comes `distance` radians close to the seam through `corner`.
/// Seen from the sphere's centre a ring side keeps its distance to the plane of its seam but
/// is farthest from the centre at its ends, so it comes closest to the seam at the corners:
/// the distance is met there and exceeded elsewhere. Bisection, as the distance shrinks
/// while the ring grows.
double ring_scale(const Vec3d& center, const Vec3d& corner, const Vec3d& seam_normal, double distance) {
    double inside = 0.0, outside = 1.0;
    for (int i = 0; i < 60; ++i) {
        const double t = 0.5 * (inside + outside);
        const Vec3d u = normalize_or_zero(center + (corner - center) * t);
        (std::asin(std::abs(dot(u, seam_normal))) > distance ? inside : outside) = t;
    }
    return inside;
}

/// Centre, fan grid up to the groove's edge, flank ring, outline; stitched inside out.
void triangulate_panel(const Polyhedron& p, const std::vector<int>& panel, const EdgeVertices& edges, int n,
                       double half_width, TriangleMesh& mesh) {
    std::vector<Vec3d> outline;
    Vec3d center(0.0);
    for (int c : panel) {
        outline.push_back(p.corners[size_t(c)]);
        center += p.corners[size_t(c)] / double(panel.size());
    }
    const Vec3d seam_normal = normalize_or_zero(cross(outline[0], outline[1]));
    const double edge_scale = ring_scale(center, outline[0], seam_normal, half_width);
    const double flank_scale = ring_scale(center, outline[0], seam_normal, half_width * kFlankFraction);

    std::vector<std::vector<int>> rings = {{int(mesh.vertices.size())}};
    mesh.vertices.push_back(center);
    for (int level = 1; level <= n; ++level)
        rings.push_back(inner_ring(outline, center, edge_scale * level / n, level, mesh.vertices));
    rings.push_back(inner_ring(outline, center, flank_scale, n, mesh.vertices));
    rings.push_back(outline_ring(panel, edges));
    for (size_t r = 0; r + 1 < rings.size(); ++r) stitch_rings(rings[r], rings[r + 1], mesh.triangles);
}

/// A seam: the great-circle arc between two corners, with the unit normal of its plane.
struct Seam {
    Vec3d a, b, normal;
};

std::vector<Seam> seams_of(const Polyhedron& p, const EdgeVertices& edges) {
    std::vector<Seam> seams;
    for (const auto& [ends, inside] : edges) {
        const Vec3d& a = p.corners[size_t(ends.first)];
        const Vec3d& b = p.corners[size_t(ends.second)];
        seams.push_back({a, b, normalize_or_zero(cross(a, b))});
    }
    return seams;
}

double angle_between(const Vec3d& u, const Vec3d& v) { return std::atan2(length(cross(u, v)), dot(u, v)); }

/// Angle between unit vector u and the seam: to its great circle where u projects inside
/// the arc, else to the nearer end.
double angle_to_seam(const Vec3d& u, const Seam& s) {
    const double across = dot(u, s.normal);
    const Vec3d q = u - s.normal * across;
    if (dot(cross(s.a, q), s.normal) >= 0 && dot(cross(q, s.b), s.normal) >= 0)
        return std::asin(std::min(1.0, std::abs(across)));
    return std::min(angle_between(u, s.a), angle_between(u, s.b));
}

/// Depth fraction across a seam: 1 on it, 0 from `half_width` on, a cosine in between so the
/// groove meets the panel without a crease.
double groove_profile(double distance, double half_width) {
    if (distance >= half_width) return 0.0;
    return 0.5 * (1.0 + std::cos(kPi * distance / half_width));
}

/// Projects every vertex onto the unit sphere, sunk by the groove of its nearest seam.
void engrave_seams(const std::vector<Seam>& seams, double depth, double half_width,
                   std::vector<Vec3d>& vertices) {
    for (Vec3d& v : vertices) {
        const Vec3d u = normalize_or_zero(v);
        double nearest = kPi;
        for (const Seam& s : seams) nearest = std::min(nearest, angle_to_seam(u, s));
        v = u * (1.0 - depth * groove_profile(nearest, half_width));
    }
}

[[noreturn]] void reject(const char* name, double value, const char* expected) {
    std::ostringstream msg;
    msg << "make_soccer_ball: " << name << " = " << value << "; expected " << expected;
    throw std::invalid_argument(msg.str());
}

/// The groove must fit well inside a pentagon (apothem 0.29 rad), leaving room for the grid.
void check_arguments(int detail, double seam_depth, double seam_width) {
    if (detail < 0) reject("detail", detail, "0 or more");
    if (!(seam_depth >= 0.0 && seam_depth < 0.5)) reject("seam_depth", seam_depth, "[0, 0.5)");
    if (!(seam_width > 0.0 && seam_width < 0.25)) reject("seam_width", seam_width, "(0, 0.25) radians");
}

}  // namespace

TriangleMesh make_soccer_ball(int detail, double seam_depth, double seam_width) {
    check_arguments(detail, seam_depth, seam_width);
    const int n = detail + 1;
    const Polyhedron p = truncated_icosahedron();

    TriangleMesh mesh;
    mesh.name = "soccer_ball";
    std::ostringstream src;
    src << "procedural soccer ball(detail=" << detail << ", seam_depth=" << seam_depth
        << ", seam_width=" << seam_width << "): truncated icosahedron on the unit sphere, engraved seams";
    mesh.source = src.str();

    mesh.vertices = p.corners;  // vertex id of corner c is c
    const EdgeVertices edges = add_edge_vertices(p, n, mesh.vertices);
    for (const std::vector<int>& panel : p.panels)
        triangulate_panel(p, panel, edges, n, seam_width / 2, mesh);
    engrave_seams(seams_of(p, edges), seam_depth, seam_width / 2, mesh.vertices);
    mesh.content_sha256 = geometry_sha256(mesh);
    return mesh;
}

}  // namespace sdf
