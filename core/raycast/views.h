/// @file views.h
/// @brief Cameras for the renders: named views fitted to a mesh's bounds, explicit
/// eye/target/up/fov cameras, and the thesis's dragon presets (Figures 5-3 and 5-4).
///
/// A named view is a direction from the target to the eye plus an up vector; the target is
/// the centre of the bounds and the distance is the smallest at which the 8 corners of the
/// bounds (or, with the points overload, every given point, e.g. the mesh's vertices)
/// project inside the image with `margin` (a fraction of the image's width and height) left
/// free on every side. Directions (mesh axes, y up):
///
///   front  +z        back  -z        side / right  +x        left  -x
///   top    +y (up -z)               bottom -y (up +z)
///   three_quarter  azimuth 45 deg from front towards right, elevation 30 deg
///   dragon_side    the thesis's Figure 5-3 (side view of the Stanford dragon, head to the
///                  left): +z
///   dragon_front   the thesis's Figure 5-4 (front view): the dragon's head (at -x) and the
///                  ridges under its belly seen from ahead, a little from above and from
///                  the +z side: (-1, 0.15, 0.35)
///
/// The field of view is vertical, in degrees (default 30).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/triangle_mesh.h"
#include "kernels/raycast/camera.h"

namespace sdf {

/// A resolved camera: everything a renderer needs, in world units.
struct CameraSpec {
    std::string name;          ///< the view's name ("front", "dragon_side", or a config's name)
    Vec3d eye{0, 0, 1}, target{0, 0, 0}, up{0, 1, 0};
    double fov_y_degrees = 30;
    int width = 512, height = 512;
};

/// A view as a config or command line asks for it: a named view fitted to the bounds, or an
/// explicit camera (explicit_camera = true: eye, target, up, fov used as given).
struct ViewRequest {
    std::string name;
    /// Named views: the view of the table it fits ("front"); `name` may rename it (a
    /// config's {"view": "front", "name": "closeup"}). Empty: `name` is the table's name.
    std::string view;
    bool explicit_camera = false;
    Vec3d eye{}, target{}, up{0, 1, 0};
    double fov_y_degrees = 30;
    double margin = 0.04;  ///< named views: free border, fraction of the image size per side
};

/// The names of the named views, in documentation order.
std::vector<std::string> named_view_names();
bool is_named_view(const std::string& name);

/// A named view request with the default fov and margin.
ViewRequest named_view(const std::string& name);

/// The camera of `request` for an image of width x height fitted to `bounds` (named views)
/// or as given (explicit). Throws std::invalid_argument for an unknown name, a degenerate
/// camera (eye == target, up parallel to the view direction), fov outside (0, 180) or a
/// non-positive size, naming the view and the value.
CameraSpec resolve_view(const ViewRequest& request, const Bounds3& bounds, int width, int height);

/// As above, fitted to the projections of `points` (e.g. a mesh's vertices: tighter than
/// the box's corners for oblique views); the target is the centre of the points' bounds.
CameraSpec resolve_view(const ViewRequest& request, const std::vector<Vec3d>& points, int width, int height);

/// The kernel camera of a spec (checks it as resolve_view does).
PinholeCamera<double> make_camera(const CameraSpec& spec);

/// {"name", "eye", "target", "up", "fov_y_degrees", "size"} for image headers and manifests.
nlohmann::json camera_to_json(const CameraSpec& spec);

}  // namespace sdf
