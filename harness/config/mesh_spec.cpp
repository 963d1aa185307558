#include "harness/config/mesh_spec.h"

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "cpu_reference/mesh/load_obj.h"
#include "cpu_reference/mesh/shapes/procedural_shapes.h"

#include "harness/build_config.h"

namespace sdf {
namespace fs = std::filesystem;

std::vector<std::string> procedural_shape_names() { return {"sphere", "box", "torus", "pawn", "soccer_ball"}; }

MeshSpec parse_mesh_spec(JsonReader& r, const std::string& key) {
    const nlohmann::json& v = r.raw(key);
    MeshSpec spec;
    if (v.is_string()) {
        spec.file = v.get<std::string>();
        if (spec.file.rfind("shape:", 0) == 0) return mesh_spec_from_argument(spec.file);
        return spec;
    }
    if (!v.is_object()) r.fail(key, "expected a file name or an object {\"file\": ...} / {\"shape\": ...}, got " + v.dump());
    JsonReader m = r.object(key);
    if (m.has("file")) {
        spec.file = m.required<std::string>("file", "a mesh file name");
        m.finish();
        return spec;
    }
    spec.shape = m.choice("shape", procedural_shape_names(), "");
    // The parameters are checked when the shape is built (each shape knows its own).
    spec.parameters = v;
    spec.parameters.erase("shape");
    return spec;
}

MeshSpec mesh_spec_from_argument(const std::string& argument) {
    MeshSpec spec;
    if (argument.rfind("shape:", 0) == 0) {
        spec.shape = argument.substr(6);
        spec.parameters = nlohmann::json::object();
    } else {
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

std::string locate_mesh_file(const std::string& name, const std::vector<std::string>& search_path) {
    if (fs::path(name).is_absolute() || fs::exists(name)) {
        if (fs::is_regular_file(name)) return name;
        throw std::runtime_error(name + ": mesh file not found");
    }
    for (const auto& dir : search_path) {
        const fs::path candidate = fs::path(dir) / name;
        if (fs::is_regular_file(candidate)) return fs::weakly_canonical(candidate).string();
    }
    std::string dirs;
    for (const auto& dir : search_path) dirs += "\n  " + dir;
    throw std::runtime_error("mesh '" + name + "' not found on the data search path:" + dirs +
                             "\nSet SDF_DATA_PATH or the config key \"data_path\", or run scripts/fetch-meshes.");
}

namespace {

TriangleMesh make_shape(const std::string& shape, const nlohmann::json& params) {
    JsonReader p(params, "mesh", "mesh");
    TriangleMesh mesh;
    auto vec3 = [&](const std::string& key, Vec3d fallback) {
        const auto v = p.optional<std::vector<double>>(key, {fallback.x, fallback.y, fallback.z}, "an array of 3 numbers");
        if (v.size() != 3) p.fail(key, "expected an array of 3 numbers");
        return Vec3d{v[0], v[1], v[2]};
    };
    if (shape == "sphere") {
        const int sub = p.optional<int>("subdivisions", 4, "an integer from 0 to 8");
        if (sub < 0 || sub > 8) p.fail("subdivisions", "expected an integer from 0 to 8, got " + std::to_string(sub));
        mesh = make_icosphere(sub, p.optional<double>("radius", 1.0, "a positive number"), vec3("center", {}));
    } else if (shape == "box") {
        mesh = make_box(vec3("half_extent", {1, 1, 1}), vec3("center", {}));
    } else if (shape == "torus") {
        mesh = make_torus(p.optional<double>("major_radius", 1.0, "a positive number"),
                          p.optional<double>("minor_radius", 0.35, "a positive number"),
                          p.optional<int>("major_segments", 64, "an integer >= 3"),
                          p.optional<int>("minor_segments", 32, "an integer >= 3"));
    } else if (shape == "pawn") {
        mesh = make_pawn(p.optional<int>("segments", 16, "an integer >= 3"));
    } else if (shape == "soccer_ball") {
        mesh = make_soccer_ball(p.optional<int>("detail", 2, "an integer >= 0"),
                                p.optional<double>("seam_depth", 0.02, "a non-negative number"),
                                p.optional<double>("seam_width", 0.03, "a positive angle in radians"));
    } else {
        throw ConfigError("mesh: unknown shape '" + shape + "'");
    }
    p.finish();
    return mesh;
}

}  // namespace

TriangleMesh load_mesh(const MeshSpec& spec, const std::vector<std::string>& search_path) {
    if (!spec.shape.empty()) {
        const auto names = procedural_shape_names();
        if (std::find(names.begin(), names.end(), spec.shape) == names.end()) {
            const std::string near = nearest_match(spec.shape, names);
            throw ConfigError("mesh: unknown procedural shape '" + spec.shape + "'" +
                              (near.empty() ? "" : "; did you mean '" + near + "'?"));
        }
        return make_shape(spec.shape, spec.parameters);
    }
    return load_obj(locate_mesh_file(spec.file, search_path));
}

}  // namespace sdf
