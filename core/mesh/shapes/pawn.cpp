// Chess pawn (thesis Fig. 5-1 E): a Staunton profile revolved about the +y axis.
//
// The profile runs from a pole on the bottom (y = 0) to a pole on top of the head (y = 1).
// Each profile point between the poles becomes a ring of `segments` vertices, except the one
// next to the top pole, which gets half as many: that ring is small, and with 16 slices this
// gives the thesis's 304 triangles exactly (10 rings of 16 would give 320, 9 rings 288).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/mesh/shapes/procedural_shapes.h"
#include "core/mesh/shapes/stitch_rings.h"

namespace sdf {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A point of the profile: distance from the axis and height.
struct ProfilePoint {
    double r, y;
};

/// The head is a sphere whose top is the top of the pawn.
constexpr double kHeadRadius = 0.18;
constexpr double kHeadCenterY = 1.0 - kHeadRadius;

/// The point of the head `degrees` down from its top.
ProfilePoint on_head(double degrees) {
    const double a = degrees * kPi / 180.0;
    return {kHeadRadius * std::sin(a), kHeadCenterY + kHeadRadius * std::cos(a)};
}

/// Bottom pole to top pole, heights increasing, so the revolved surface cannot cross itself.
std::vector<ProfilePoint> staunton_profile() {
    return {
        {0.0, 0.0},                                     // bottom pole
        {0.30, 0.0},   {0.30, 0.05},                    // base disc: flat bottom, upright rim
        {0.25, 0.11},                                   // bevel up to the base's shoulder
        {0.155, 0.24}, {0.10, 0.50},                    // concave waist, narrowest under the collar
        {0.19, 0.575},                                  // collar rim
        on_head(150.0),                                 // neck, where the head sits on the collar
        on_head(115.0), on_head(75.0), on_head(35.0),   // round head
        {0.0, 1.0},                                     // top pole
    };
}

/// Vertices of profile point i: one on the axis, half the slices next to the top pole.
int slices_at(const std::vector<ProfilePoint>& profile, size_t i, int segments) {
    if (profile[i].r == 0.0) return 1;
    if (i + 2 == profile.size()) return std::max(3, segments / 2);
    return segments;
}

/// Adds a ring of `slices` vertices evenly spaced around the axis; returns their ids.
std::vector<int> add_ring(const ProfilePoint& p, int slices, std::vector<Vec3d>& vertices) {
    std::vector<int> ring;
    for (int k = 0; k < slices; ++k) {
        const double a = 2.0 * kPi * k / slices;
        ring.push_back(int(vertices.size()));
        vertices.push_back({p.r * std::cos(a), p.y, p.r * std::sin(a)});
    }
    return ring;
}

}  // namespace

TriangleMesh make_pawn(int segments) {
    if (segments < 3)
        throw std::invalid_argument("make_pawn: segments = " + std::to_string(segments) +
                                    "; expected at least 3");
    const std::vector<ProfilePoint> profile = staunton_profile();
    TriangleMesh mesh;
    mesh.name = "pawn";
    std::ostringstream src;
    src << "procedural pawn(segments=" << segments << "): Staunton profile of " << profile.size()
        << " points revolved about +y, base on y=0, height 1";
    mesh.source = src.str();

    std::vector<std::vector<int>> rings;
    for (size_t i = 0; i < profile.size(); ++i)
        rings.push_back(add_ring(profile[i], slices_at(profile, i, segments), mesh.vertices));
    for (size_t i = 0; i + 1 < rings.size(); ++i) stitch_rings(rings[i], rings[i + 1], mesh.triangles);
    mesh.content_sha256 = geometry_sha256(mesh);
    return mesh;
}

}  // namespace sdf
