#include "core/mesh/mesh_provenance.h"

#include <stdexcept>

#include "core/mesh/prepared_mesh.h"

namespace sdf {

namespace {

nlohmann::json xyz(const Vec3d& v) { return {v.x, v.y, v.z}; }

[[noreturn]] void wrong(const std::string& key, const char* expected, const nlohmann::json& got) {
    throw std::runtime_error((key.empty() ? "mesh" : "mesh." + key) + ": expected " + expected + ", got " + got.dump());
}

std::string text(const nlohmann::json& j, const char* key) {
    if (!j.contains(key)) return "";
    if (!j[key].is_string()) wrong(key, "a string", j[key]);
    return j[key].get<std::string>();
}

int64_t count(const nlohmann::json& j, const char* key) {
    if (!j.contains(key)) return 0;
    if (!j[key].is_number_integer()) wrong(key, "an integer", j[key]);
    return j[key].get<int64_t>();
}

Vec3d point(const nlohmann::json& j, const std::string& key) {
    if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
        wrong(key, "[x, y, z]", j);
    return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

}  // namespace

nlohmann::json mesh_report_to_json(const MeshReport& r) {
    return {{"input_vertices", r.input_vertices},
            {"input_triangles", r.input_triangles},
            {"welded_vertices", r.welded_vertices},
            {"degenerate_triangles", r.degenerate_triangles},
            {"polygons", r.polygons.polygons},
            {"non_planar_polygons", r.polygons.non_planar},
            {"max_polygon_non_planarity", r.polygons.max_non_planarity},
            {"non_simple_polygons", r.polygons.not_simple},
            {"boundary_edges", r.boundary_edges},
            {"nonmanifold_edges", r.nonmanifold_edges},
            {"inconsistent_edges", r.inconsistent_edges},
            {"slivers_within_rounding", r.slivers_within_rounding},
            {"components", r.components},
            {"signed_volume", r.signed_volume},
            {"flipped", r.flipped},
            {"sign_reliable", r.sign_reliable()}};
}

MeshProvenance describe_prepared_mesh(const PreparedMesh& mesh) {
    MeshProvenance m;
    m.name = mesh.name();
    m.source = mesh.source();
    m.sha256 = mesh.content_sha256();
    m.vertices = int64_t(mesh.vertices().size());
    m.triangles = int64_t(mesh.triangles().size());
    m.has_bounds = true;
    m.bounds = mesh.bounds();
    m.report = mesh_report_to_json(mesh.report());
    return m;
}

void to_json(nlohmann::json& j, const MeshProvenance& m) {
    if (m.empty()) {
        j = nlohmann::json::object();
        return;
    }
    j = {{"name", m.name}, {"source", m.source}, {"sha256", m.sha256}, {"vertices", m.vertices}, {"triangles", m.triangles}};
    if (m.has_bounds) j["bounds"] = {{"min", xyz(m.bounds.min)}, {"max", xyz(m.bounds.max)}};
    j["report"] = m.report;
}

void from_json(const nlohmann::json& j, MeshProvenance& m) {
    m = MeshProvenance();
    if (j.is_null()) return;
    if (!j.is_object()) wrong("", "an object", j);
    m.name = text(j, "name");
    m.source = text(j, "source");
    m.sha256 = text(j, "sha256");
    m.vertices = count(j, "vertices");
    m.triangles = count(j, "triangles");
    if (j.contains("bounds")) {
        const nlohmann::json& b = j["bounds"];
        if (!b.is_object() || !b.contains("min") || !b.contains("max")) wrong("bounds", "{\"min\", \"max\"}", b);
        m.has_bounds = true;
        m.bounds.min = point(b["min"], "bounds.min");
        m.bounds.max = point(b["max"], "bounds.max");
    }
    if (j.contains("report")) {
        if (!j["report"].is_object()) wrong("report", "an object", j["report"]);
        m.report = j["report"];
    }
    for (const char* key : {"components", "sign_reliable"})  // the shorter record of earlier versions
        if (j.contains(key) && !m.report.contains(key)) m.report[key] = j[key];
}

}  // namespace sdf
