#include "core/raycast/views.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace sdf {
namespace {

struct NamedView {
    const char* name;
    Vec3d direction;  ///< from the target towards the eye
    Vec3d up;
};

// Directions need not be unit length; they are normalised when used.
const NamedView kNamedViews[] = {
    {"front", {0, 0, 1}, {0, 1, 0}},
    {"back", {0, 0, -1}, {0, 1, 0}},
    {"side", {1, 0, 0}, {0, 1, 0}},
    {"right", {1, 0, 0}, {0, 1, 0}},
    {"left", {-1, 0, 0}, {0, 1, 0}},
    {"top", {0, 1, 0}, {0, 0, -1}},
    {"bottom", {0, -1, 0}, {0, 0, 1}},
    {"three_quarter", {0.61237243569579, 0.5, 0.61237243569579}, {0, 1, 0}},  // az 45, el 30
    {"dragon_side", {0, 0, 1}, {0, 1, 0}},
    {"dragon_front", {-1.0, 0.15, 0.35}, {0, 1, 0}},  // the head is at -x
};

const NamedView& find_named_view(const std::string& name) {
    for (const NamedView& v : kNamedViews)
        if (name == v.name) return v;
    std::string known;
    for (const NamedView& v : kNamedViews) known += std::string(known.empty() ? "" : ", ") + v.name;
    throw std::invalid_argument("view '" + name + "': unknown view name; expected one of " + known +
                                " or an explicit camera (eye, target, up, fov)");
}

std::string number_text(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", v);
    return text;
}

bool finite(const Vec3d& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

std::string vec_text(const Vec3d& v) {
    std::ostringstream s;
    s << "[" << v.x << ", " << v.y << ", " << v.z << "]";
    return s.str();
}

void check_size_and_fov(const std::string& view, int width, int height, double fov) {
    if (width < 1 || height < 1)
        throw std::invalid_argument("view '" + view + "': image size " + std::to_string(width) + "x" +
                                    std::to_string(height) + " is not positive");
    if (!(fov > 0 && fov < 180))
        throw std::invalid_argument("view '" + view + "': fov " + number_text(fov) + " degrees is outside (0, 180)");
    // Neighbouring pixels' rays differ by about 2 tan(fov / 2) / size: below ~1e-12 they
    // are the same ray in double (and a fitted eye flies off beyond double's range).
    const double step = 2 * std::tan(fov * M_PI / 360.0) / double(std::max(width, height));
    if (!(step > 1e-12))
        throw std::invalid_argument("view '" + view + "': fov " + number_text(fov) + " degrees is too small for a " +
                                    std::to_string(width) + "x" + std::to_string(height) +
                                    " image: neighbouring pixels' rays would differ by " + number_text(step) +
                                    " radians, below double precision; expected a fov of at least " +
                                    number_text(1e-12 * double(std::max(width, height)) * 180.0 / M_PI) + " degrees");
}

/// Distance from `centre` along `direction` at which every point projects inside the image.
double fitted_distance(const std::vector<Vec3d>& points, const Vec3d& centre, const Vec3d& direction, const Vec3d& up,
                       double fov_y_degrees, double aspect, double margin) {
    const Vec3d back = normalize_or_zero(direction);
    const Vec3d right = normalize_or_zero(cross(-back, up));
    const Vec3d true_up = cross(right, -back);
    const double fill = std::max(1e-3, 1.0 - 2.0 * margin);
    const double tan_y = std::tan(fov_y_degrees * M_PI / 360.0) * fill;
    const double tan_x = tan_y * aspect;
    double distance = 0, extent = 0;
    for (const Vec3d& p : points) {
        const Vec3d q = p - centre;
        const double z = dot(q, back);  // towards the eye
        distance = std::max({distance, z + std::abs(dot(q, right)) / tan_x, z + std::abs(dot(q, true_up)) / tan_y});
        extent = std::max(extent, length(q));
    }
    // A point-like set still needs a positive distance
    return std::max(distance, 1e-6 * std::max(1.0, extent));
}

std::vector<Vec3d> corners(const Bounds3& b) {
    std::vector<Vec3d> c;
    for (int k = 0; k < 8; ++k)
        c.push_back({k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y, k & 4 ? b.max.z : b.min.z});
    return c;
}

CameraSpec fit_named_view(const ViewRequest& request, const std::vector<Vec3d>& points, const Bounds3& bounds,
                          int width, int height) {
    check_size_and_fov(request.name, width, height, request.fov_y_degrees);
    if (bounds.empty()) throw std::invalid_argument("view '" + request.name + "': the bounds to fit are empty");
    if (!(request.margin >= 0 && request.margin < 0.5))
        throw std::invalid_argument("view '" + request.name + "': margin " + std::to_string(request.margin) +
                                    " is outside [0, 0.5)");
    const NamedView& v = find_named_view(request.view.empty() ? request.name : request.view);
    CameraSpec c;
    c.name = request.name;
    c.fov_y_degrees = request.fov_y_degrees;
    c.width = width;
    c.height = height;
    c.target = bounds.center();
    c.eye = c.target + normalize_or_zero(v.direction) *
                           fitted_distance(points, c.target, v.direction, v.up, request.fov_y_degrees,
                                           double(width) / height, request.margin);
    c.up = v.up;
    if (!finite(c.eye))
        throw std::invalid_argument("view '" + request.name + "': the bounds " + vec_text(bounds.min) + " to " +
                                    vec_text(bounds.max) + " cannot be framed at fov " + number_text(request.fov_y_degrees) +
                                    " degrees: the fitted eye's distance overflows double; expected a larger fov");
    return c;
}

}  // namespace

std::vector<std::string> named_view_names() {
    std::vector<std::string> names;
    for (const NamedView& v : kNamedViews) names.emplace_back(v.name);
    return names;
}

bool is_named_view(const std::string& name) {
    for (const NamedView& v : kNamedViews)
        if (name == v.name) return true;
    return false;
}

ViewRequest named_view(const std::string& name) {
    find_named_view(name);  // throws for unknown names
    ViewRequest r;
    r.name = name;
    r.view = name;
    return r;
}

CameraSpec resolve_view(const ViewRequest& request, const Bounds3& bounds, int width, int height) {
    check_size_and_fov(request.name, width, height, request.fov_y_degrees);
    CameraSpec c;
    if (request.explicit_camera) {
        c.name = request.name;
        c.fov_y_degrees = request.fov_y_degrees;
        c.width = width;
        c.height = height;
        c.eye = request.eye;
        c.target = request.target;
        c.up = request.up;
    } else {
        c = fit_named_view(request, corners(bounds), bounds, width, height);
    }
    make_camera(c);  // validates
    return c;
}

CameraSpec resolve_view(const ViewRequest& request, const std::vector<Vec3d>& points, int width, int height) {
    if (request.explicit_camera || points.empty()) return resolve_view(request, Bounds3{}, width, height);
    Bounds3 bounds;
    for (const Vec3d& p : points) bounds.extend(p);
    CameraSpec c = fit_named_view(request, points, bounds, width, height);
    make_camera(c);
    return c;
}

PinholeCamera<double> make_camera(const CameraSpec& spec) {
    check_size_and_fov(spec.name, spec.width, spec.height, spec.fov_y_degrees);
    // Each problem by its name (a NaN or overflowing eye used to read as "up parallel").
    for (const auto& [what, v] : {std::pair{"eye", spec.eye}, {"target", spec.target}, {"up", spec.up}})
        if (!finite(v))
            throw std::invalid_argument("view '" + spec.name + "': " + what + " " + vec_text(v) +
                                        " is not finite; expected three finite numbers");
    const Vec3d forward = spec.target - spec.eye;
    if (!std::isfinite(length(forward)))
        throw std::invalid_argument("view '" + spec.name + "': eye " + vec_text(spec.eye) + " and target " +
                                    vec_text(spec.target) + " are too far apart: their distance overflows double");
    if (!std::isfinite(length(spec.up)))
        throw std::invalid_argument("view '" + spec.name + "': up " + vec_text(spec.up) +
                                    " is too long: its length overflows double; expected a direction such as [0, 1, 0]");
    if (!(length(forward) > 0))
        throw std::invalid_argument("view '" + spec.name + "': eye " + vec_text(spec.eye) + " equals target " +
                                    vec_text(spec.target));
    if (!(length(cross(normalize_or_zero(forward), normalize_or_zero(spec.up))) > 1e-6))
        throw std::invalid_argument("view '" + spec.name + "': up " + vec_text(spec.up) +
                                    " is zero or parallel to the view direction " + vec_text(forward));
    return make_look_at_camera(spec.eye, spec.target, spec.up, spec.fov_y_degrees, spec.width, spec.height);
}

nlohmann::json camera_to_json(const CameraSpec& spec) {
    auto v = [](const Vec3d& p) { return nlohmann::json::array({p.x, p.y, p.z}); };
    return {{"name", spec.name},          {"eye", v(spec.eye)},
            {"target", v(spec.target)},   {"up", v(spec.up)},
            {"fov_y_degrees", spec.fov_y_degrees}, {"size", {spec.width, spec.height}}};
}

}  // namespace sdf
