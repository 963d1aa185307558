#include "harness/config/render_spec.h"

#include <stdexcept>

#include "core/reconstruction/reconstruction_spec.h"
#include "harness/render/render_backend.h"

namespace sdf {
namespace {

Vec3d read_vec3(JsonReader& r, const std::string& key, const Vec3d& fallback, bool required) {
    const std::string expected = "an array of 3 numbers";
    const std::vector<double> v = required ? r.required<std::vector<double>>(key, expected)
                                           : r.optional<std::vector<double>>(key, {fallback.x, fallback.y, fallback.z}, expected);
    if (v.size() != 3) r.fail(key, "expected " + expected + ", got " + nlohmann::json(v).dump());
    return {v[0], v[1], v[2]};
}

double read_fov(JsonReader& r, double fallback) {
    const double fov = r.optional<double>("fov", fallback, "a vertical field of view in degrees, in (0, 180)");
    if (!(fov > 0 && fov < 180)) r.fail("fov", "expected a vertical field of view in degrees in (0, 180), got " + std::to_string(fov));
    return fov;
}

double read_margin(JsonReader& r, double fallback) {
    const double m = r.optional<double>("margin", fallback, "a free border as a fraction of the image size, in [0, 0.5)");
    if (!(m >= 0 && m < 0.5)) r.fail("margin", "expected a fraction of the image size in [0, 0.5), got " + std::to_string(m));
    return m;
}

std::string known_views() {
    std::string s;
    for (const std::string& n : named_view_names()) s += (s.empty() ? "" : ", ") + n;
    return s;
}

ViewRequest named(JsonReader& r, const std::string& key, const std::string& name, double fov, double margin) {
    if (!is_named_view(name))
        r.fail(key, "unknown view \"" + name + "\"; expected one of " + known_views() +
                        " or an object with eye, target, up and fov");
    ViewRequest v = named_view(name);
    v.fov_y_degrees = fov;
    v.margin = margin;
    return v;
}

/// One entry of "views": a name, {"view": name, "fov", "margin"} or an explicit camera.
ViewRequest parse_view(JsonReader& parent, const nlohmann::json& entry, size_t index, double fov, double margin) {
    const std::string key = "views[" + std::to_string(index) + "]";
    if (entry.is_string()) return named(parent, key, entry.get<std::string>(), fov, margin);
    if (!entry.is_object())
        parent.fail(key, "expected a view name or an object (explicit camera or {\"view\": name}), got " + entry.dump());
    JsonReader r(entry, parent.file(), parent.key_path(key));
    ViewRequest v;
    if (r.has("view")) {
        const std::string name = r.required<std::string>("view", "a named view");
        v = named(r, "view", name, read_fov(r, fov), read_margin(r, margin));
        v.name = r.optional<std::string>("name", name, "a name for the view");  // v.view stays the table's name
    } else {
        v.explicit_camera = true;
        v.name = r.required<std::string>("name", "a name for the explicit camera");
        v.eye = read_vec3(r, "eye", {}, true);
        v.target = read_vec3(r, "target", {}, true);
        v.up = read_vec3(r, "up", {0, 1, 0}, false);
        v.fov_y_degrees = read_fov(r, fov);
        if (length(v.target - v.eye) == 0) r.fail("target", "the target equals the eye");
        if (length(cross(v.target - v.eye, v.up)) == 0) r.fail("up", "up is zero or parallel to the view direction");
    }
    r.finish();
    return v;
}

/// One entry of "panels", with errors naming it.
RenderPanelRequest parse_panel(JsonReader& r, const nlohmann::json& entry, size_t index) {
    const std::string key = "panels[" + std::to_string(index) + "]";
    if (!entry.is_string())
        r.fail(key, "expected \"interpolator\" or \"interpolator/derivatives\", got " + entry.dump());
    try {
        return parse_panel_request(entry.get<std::string>());
    } catch (const std::invalid_argument& e) {
        r.fail(key, e.what());
    }
}

}  // namespace

RenderPanelRequest parse_panel_request(const std::string& text) {
    const size_t slash = text.find('/');
    RenderPanelRequest p;
    p.interpolator = text.substr(0, slash);
    try {
        ReconstructionSpec spec;
        spec.interpolator = parse_interpolator(p.interpolator);
        spec.derivatives = slash == std::string::npos ? default_derivative_source(spec.interpolator, true)
                                                      : parse_derivative_source(text.substr(slash + 1));
        Lattice probe;  // large enough for every filter: only the names and sources are checked here
        probe.type = interpolator_lattice(spec.interpolator);
        probe.resolution = {16, 16, 16};
        validate_reconstruction(spec, probe, /*field_has_gradient=*/true);
        p.derivatives = derivative_source_name(spec.derivatives);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("\"" + text + "\": " + e.what());
    }
    return p;
}

RenderSpec parse_render_spec(JsonReader& r) {
    RenderSpec s;
    if (r.has("size")) {
        const nlohmann::json& size = r.raw("size");
        std::vector<int> wh;
        if (size.is_number_integer()) wh = {size.get<int>(), size.get<int>()};
        else wh = r.required<std::vector<int>>("size", "[width, height] in pixels or one integer");
        if (wh.size() != 2 || wh[0] < 1 || wh[1] < 1 || wh[0] > 16384 || wh[1] > 16384)
            r.fail("size", "expected [width, height] with entries in 1..16384 (or one integer), got " + size.dump());
        s.width = wh[0];
        s.height = wh[1];
        r.record("size", {s.width, s.height});
    }
    const double fov = read_fov(r, 30.0);
    const double margin = read_margin(r, 0.04);
    if (r.has("views")) {
        const nlohmann::json& views = r.raw("views");
        if (!views.is_array() || views.empty())
            r.fail("views", "expected a non-empty array of view names or camera objects, got " + views.dump());
        s.views.clear();
        for (size_t i = 0; i < views.size(); ++i) s.views.push_back(parse_view(r, views[i], i, fov, margin));
        r.record("views", views);
    } else {
        s.views = {named(r, "views", "three_quarter", fov, margin)};
    }
    s.reference = r.optional<bool>("reference", s.reference, "true or false");
    s.error_maps = r.optional<bool>("error_maps", s.error_maps, "true or false");
    s.heat_max_degrees = r.optional<double>("heat_max_degrees", s.heat_max_degrees, "a positive angle in degrees");
    if (!(s.heat_max_degrees > 0)) r.fail("heat_max_degrees", "expected a positive angle in degrees, got " + std::to_string(s.heat_max_degrees));
    s.backend = r.choice("backend", render_backend_choices(), s.backend);
    s.precision = r.choice("precision", {"float", "double"}, s.precision);
    s.grid_downsample = r.optional<int>("grid_downsample", s.grid_downsample, "an integer factor >= 1");
    if (s.grid_downsample < 1) r.fail("grid_downsample", "expected an integer factor >= 1, got " + std::to_string(s.grid_downsample));
    if (r.has("panels")) {
        const nlohmann::json& panels = r.raw("panels");
        if (!panels.is_array() || panels.empty() || panels.size() > 26)
            r.fail("panels", "expected an array of 1 to 26 reconstructions (\"interpolator\" or "
                             "\"interpolator/derivatives\"), got " + panels.dump());
        nlohmann::json resolved = nlohmann::json::array();
        for (size_t i = 0; i < panels.size(); ++i) {
            s.panels.push_back(parse_panel(r, panels[i], i));
            const std::string id = s.panels.back().interpolator + "/" + s.panels.back().derivatives;
            for (size_t j = 0; j + 1 < s.panels.size(); ++j)
                if (s.panels[j].interpolator + "/" + s.panels[j].derivatives == id)
                    r.fail("panels[" + std::to_string(i) + "]", "\"" + id + "\" is already panel " + std::string(1, char('A' + j)));
            resolved.push_back(id);
        }
        r.record("panels", resolved);
    }
    r.finish();
    return s;
}

RenderSpec render_spec_from_json(const nlohmann::json& j, const std::string& source) {
    JsonReader r(j, source, "render");
    return parse_render_spec(r);
}

namespace {

nlohmann::json vec3_json(const Vec3d& v) { return {v.x, v.y, v.z}; }

nlohmann::json view_to_json(const ViewRequest& v) {
    if (v.explicit_camera)
        return {{"name", v.name}, {"eye", vec3_json(v.eye)}, {"target", vec3_json(v.target)}, {"up", vec3_json(v.up)},
                {"fov", v.fov_y_degrees}};
    const std::string view = v.view.empty() ? v.name : v.view;
    nlohmann::json j = {{"view", view}, {"fov", v.fov_y_degrees}, {"margin", v.margin}};
    if (v.name != view) j["name"] = v.name;
    return j;
}

}  // namespace

nlohmann::json render_spec_to_json(const RenderSpec& s) {
    nlohmann::json views = nlohmann::json::array();
    for (const ViewRequest& v : s.views) views.push_back(view_to_json(v));
    nlohmann::json j = {{"size", {s.width, s.height}},
                        {"views", views},
                        {"reference", s.reference},
                        {"error_maps", s.error_maps},
                        {"heat_max_degrees", s.heat_max_degrees},
                        {"backend", s.backend},
                        {"precision", s.precision},
                        {"grid_downsample", s.grid_downsample}};
    if (!s.panels.empty()) {
        nlohmann::json panels = nlohmann::json::array();
        for (const RenderPanelRequest& p : s.panels) panels.push_back(p.interpolator + "/" + p.derivatives);
        j["panels"] = panels;
    }
    return j;
}

RenderOptions render_options(const RenderSpec& s) {
    RenderOptions o;
    o.backend = s.backend;
    o.precision = s.precision == "double" ? Precision::Double : Precision::Float;
    return o;
}

}  // namespace sdf
