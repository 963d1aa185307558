#include "harness/config/mesh_spec.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <sstream>

#include "core/io/text_file.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"

#include "harness/build_config.h"

namespace sdf {
namespace fs = std::filesystem;

std::vector<std::string> procedural_shape_names() { return {"sphere", "box", "torus", "pawn", "soccer_ball"}; }

namespace {

std::string number(double v) {
    std::ostringstream s;
    s.precision(17);
    s << v;
    return s.str();
}

std::string shape_list() {
    std::string list;
    for (const auto& n : procedural_shape_names()) list += (list.empty() ? "" : ", ") + n;
    return list;
}

/// Throws unless `name` is a procedural shape; `who` prefixes the message.
void check_shape_name(const std::string& name, const std::string& who) {
    const auto names = procedural_shape_names();
    if (name.empty()) throw ConfigError(who + ": \"shape:\" needs a shape name after the colon (one of " + shape_list() + ")");
    if (std::find(names.begin(), names.end(), name) != names.end()) return;
    const std::string near = nearest_match(name, names);
    throw ConfigError(who + ": unknown procedural shape '" + name + "'" +
                      (near.empty() ? "" : "; did you mean '" + near + "'?") + " (known: " + shape_list() + ")");
}

// ---- shape parameters: read, range-checked, and turned into a builder ----------------------

double positive(JsonReader& p, const std::string& key, double fallback) {
    const double v = p.optional<double>(key, fallback, "a positive number");
    if (!(v > 0) || !std::isfinite(v)) p.fail(key, "expected a positive number, got " + number(v));
    return v;
}

int integer_in(JsonReader& p, const std::string& key, int fallback, int lo, int hi) {
    const std::string expected = "an integer from " + std::to_string(lo) + " to " + std::to_string(hi);
    const int v = p.optional<int>(key, fallback, expected);
    if (v < lo || v > hi) p.fail(key, "expected " + expected + ", got " + std::to_string(v));
    return v;
}

Vec3d vec3(JsonReader& p, const std::string& key, Vec3d fallback, bool positive_entries) {
    const std::string expected = positive_entries ? "an array of 3 positive numbers" : "an array of 3 numbers";
    const auto v = p.optional<std::vector<double>>(key, {fallback.x, fallback.y, fallback.z}, expected);
    if (v.size() != 3) p.fail(key, "expected " + expected + ", got " + p.raw(key).dump());
    if (positive_entries && !(v[0] > 0 && v[1] > 0 && v[2] > 0))
        p.fail(key, "expected " + expected + ", got " + p.raw(key).dump());
    return {v[0], v[1], v[2]};
}

/// Reads the parameters of `shape` from `p` (every error names p's file and key path), checks
/// their ranges, rejects unknown keys, and returns the function that builds the mesh.
std::function<TriangleMesh()> read_shape(const std::string& shape, JsonReader& p) {
    std::function<TriangleMesh()> build;
    if (shape == "sphere") {
        const int sub = integer_in(p, "subdivisions", 4, 0, 8);
        const double radius = positive(p, "radius", 1.0);
        const Vec3d center = vec3(p, "center", {}, false);
        build = [=] { return make_icosphere(sub, radius, center); };
    } else if (shape == "box") {
        const Vec3d half = vec3(p, "half_extent", {1, 1, 1}, true);
        const Vec3d center = vec3(p, "center", {}, false);
        build = [=] { return make_box(half, center); };
    } else if (shape == "torus") {
        const double major = positive(p, "major_radius", 1.0);
        const double minor = positive(p, "minor_radius", 0.35);
        if (!(minor < major))
            p.fail("minor_radius", "expected a tube radius below major_radius (" + number(major) +
                                       "; a larger one makes the torus intersect itself), got " + number(minor));
        const int major_segments = integer_in(p, "major_segments", 64, 3, 4096);
        const int minor_segments = integer_in(p, "minor_segments", 32, 3, 4096);
        build = [=] { return make_torus(major, minor, major_segments, minor_segments); };
    } else if (shape == "pawn") {
        const int segments = integer_in(p, "segments", 16, 3, 4096);
        build = [=] { return make_pawn(segments); };
    } else if (shape == "soccer_ball") {
        const int detail = integer_in(p, "detail", 2, 0, 100);
        const double depth = p.optional<double>("seam_depth", 0.02, "a depth from 0 to below 0.5 (ball radius 1)");
        if (!(depth >= 0 && depth < 0.5))
            p.fail("seam_depth", "expected a depth from 0 to below 0.5 (the ball's radius is 1), got " + number(depth));
        const double width = positive(p, "seam_width", 0.03);
        build = [=] { return make_soccer_ball(detail, depth, width); };
    } else {
        check_shape_name(shape, p.file() + ": key '" + p.path() + "'");
    }
    p.finish({"shape"});
    return build;
}

std::function<TriangleMesh()> shape_builder(const MeshSpec& spec) {
    JsonReader p(spec.parameters, spec.config_file, spec.key_path);
    return read_shape(spec.shape, p);
}

}  // namespace

MeshSpec parse_mesh_spec(JsonReader& r, const std::string& key) {
    const nlohmann::json& v = r.raw(key);
    MeshSpec spec;
    spec.config_file = r.file();
    spec.key_path = r.key_path(key);
    if (v.is_string()) {
        const std::string s = v.get<std::string>();
        if (s.rfind("shape:", 0) == 0) {
            check_shape_name(s.substr(6), r.file() + ": key '" + spec.key_path + "'");
            spec.shape = s.substr(6);
        } else {
            if (s.empty()) r.fail(key, "expected a mesh file name, got \"\"");
            spec.file = s;
        }
        return spec;
    }
    if (!v.is_object()) r.fail(key, "expected a file name or an object {\"file\": ...} / {\"shape\": ...}, got " + v.dump());
    JsonReader m = r.object(key);
    const bool has_file = m.has("file"), has_shape = m.has("shape");
    if (has_file && has_shape)
        r.fail(key, "give either 'file' or 'shape', not both; got " + v.dump());
    if (!has_file && !has_shape)
        r.fail(key, "expected {\"file\": NAME} or {\"shape\": NAME, parameters...}, got " + v.dump());
    if (has_file) {
        spec.file = m.required<std::string>("file", "a mesh file name");
        if (spec.file.empty()) m.fail("file", "expected a mesh file name, got \"\"");
        m.finish();
        return spec;
    }
    spec.shape = m.choice("shape", procedural_shape_names(), "");
    spec.parameters = v;
    spec.parameters.erase("shape");
    read_shape(spec.shape, m);  // checks every parameter now; records the defaults
    return spec;
}

MeshSpec mesh_spec_from_argument(const std::string& argument) {
    MeshSpec spec;
    if (argument.rfind("shape:", 0) == 0) {
        check_shape_name(argument.substr(6), "mesh argument \"" + argument + "\"");
        spec.shape = argument.substr(6);
    } else {
        if (argument.empty()) throw ConfigError("mesh argument: expected a mesh file name or shape:NAME, got \"\"");
        spec.file = argument;
    }
    return spec;
}

std::vector<std::string> data_search_path(const std::vector<std::string>& config_entries, const std::string& config_dir) {
    std::vector<std::string> path;
    for (const auto& e : config_entries) path.push_back(fs::path(e).is_absolute() || config_dir.empty() ? e : (fs::path(config_dir) / e).string());
    if (const char* env = std::getenv("SDF_DATA_PATH")) {
        std::stringstream ss(env);
        for (std::string item; std::getline(ss, item, ':');)
            if (!item.empty()) path.push_back(item);
    }
    std::stringstream defaults(SDF_DATA_DIR_DEFAULT);
    for (std::string item; std::getline(defaults, item, '|');)
        if (!item.empty()) path.push_back(item);
    return path;
}

std::string locate_mesh_file(const std::string& name, const std::vector<std::string>& search_path,
                             const std::string& base_dir) {
    if (fs::path(name).is_absolute()) {
        require_regular_file(name, "mesh file");
        return name;
    }
    std::vector<fs::path> tried;
    if (!base_dir.empty()) tried.push_back(fs::path(base_dir) / name);
    for (const auto& dir : search_path) tried.push_back(fs::path(dir) / name);
    for (const fs::path& candidate : tried)
        if (fs::is_regular_file(candidate)) return fs::weakly_canonical(fs::absolute(candidate)).string();
    std::string places;
    for (const fs::path& c : tried) {
        const std::string kind = file_kind(c.string());
        places += "\n  " + c.string() + (kind == "missing" ? "" : " (" + kind + ", not a regular file)");
    }
    throw MeshFileNotFound("mesh '" + name + "' not found; tried, in order:" + places +
                             "\nSet SDF_DATA_PATH or the config key \"data_path\", or run scripts/fetch-meshes.");
}

void resolve_mesh_file(MeshSpec& spec, const std::vector<std::string>& search_path, const std::string& base_dir) {
    if (spec.file.empty() || !spec.resolved_file.empty()) return;
    try {
        spec.resolved_file = locate_mesh_file(spec.file, search_path, base_dir);
    } catch (const MeshFileNotFound& e) {
        throw MeshFileNotFound(spec.config_file + ": key '" + spec.key_path + "': " + e.what());
    } catch (const std::exception& e) {
        throw ConfigError(spec.config_file + ": key '" + spec.key_path + "': " + e.what());
    }
}

TriangleMesh load_mesh(const MeshSpec& spec, const std::vector<std::string>& search_path, const std::string& base_dir) {
    if (!spec.shape.empty() || spec.file.empty()) {
        check_shape_name(spec.shape, spec.config_file + ": key '" + spec.key_path + "'");
        return shape_builder(spec)();
    }
    const std::string path = spec.resolved_file.empty() ? locate_mesh_file(spec.file, search_path, base_dir) : spec.resolved_file;
    return load_mesh_file(path);
}

}  // namespace sdf
