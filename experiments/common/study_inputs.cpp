#include "experiments/common/study_inputs.h"

#include <iostream>

#include "harness/config/sampler_spec.h"

namespace sdf {

StudyInputs read_study_inputs(JsonReader& config, const RunContext& context, bool lattices_required) {
    StudyInputs in;
    in.mesh = parse_mesh_spec(config, "mesh");
    const auto data_path = config.optional<std::vector<std::string>>("data_path", {}, "an array of directories");
    in.search_path = data_search_path(data_path, context.config_dir);
    if (config.has("domain")) {
        JsonReader domain = config.object("domain");
        in.margin = domain.optional<double>("margin", 0.1, "a margin as a fraction of the mesh's largest extent");
        if (in.margin < 0) domain.fail("margin", "expected a non-negative fraction");
        domain.finish();
    }
    if (lattices_required || config.has("lattices"))
        for (JsonReader& l : config.objects("lattices")) {
            in.lattices.push_back(parse_lattice_spec(l));
            l.finish();
        }
    if (config.has("sampler")) {
        JsonReader s = config.object("sampler");
        in.sampler = parse_sampler_options(s);
    }
    return in;
}

nlohmann::json describe_mesh(const PreparedMesh& m) {
    const MeshReport& r = m.report;
    return {{"name", m.name},
            {"source", m.source},
            {"sha256", m.content_sha256},
            {"vertices", m.vertices.size()},
            {"triangles", m.triangles.size()},
            {"bounds", {{"min", {m.bounds.min.x, m.bounds.min.y, m.bounds.min.z}},
                        {"max", {m.bounds.max.x, m.bounds.max.y, m.bounds.max.z}}}},
            {"report", {{"input_vertices", r.input_vertices},
                        {"input_triangles", r.input_triangles},
                        {"welded_vertices", r.welded_vertices},
                        {"degenerate_triangles", r.degenerate_triangles},
                        {"boundary_edges", r.boundary_edges},
                        {"nonmanifold_edges", r.nonmanifold_edges},
                        {"inconsistent_edges", r.inconsistent_edges},
                        {"components", r.components},
                        {"signed_volume", r.signed_volume},
                        {"flipped", r.flipped},
                        {"sign_reliable", r.sign_reliable()}}}};
}

PreparedMesh load_prepared_mesh(const StudyInputs& inputs, std::ostream& log) {
    PreparedMesh mesh = prepare_mesh(load_mesh(inputs.mesh, inputs.search_path));
    const MeshReport& r = mesh.report;
    log << "mesh " << mesh.name << " (" << mesh.source << "): " << mesh.vertices.size() << " vertices, "
        << mesh.triangles.size() << " triangles, " << r.components << " component(s), "
        << (r.closed() ? "closed" : "open") << (r.consistently_oriented() ? ", consistently oriented" : ", INCONSISTENT orientation")
        << "\n";
    for (const std::string& w : mesh.warnings()) std::cerr << "warning: " << w << "\n";
    return mesh;
}

}  // namespace sdf
