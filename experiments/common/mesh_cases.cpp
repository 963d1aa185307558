#include "experiments/common/mesh_cases.h"

#include "harness/study/study_inputs.h"

namespace sdf {
namespace {

MeshCase read_mesh_case(JsonReader& c, const std::vector<std::string>& search_path, const std::string& base_dir) {
    MeshCase spec;
    spec.label = c.required<std::string>("label", "a mesh label such as \"dragon\"");
    spec.mesh = parse_mesh_spec(c, "mesh");
    resolve_mesh_file(spec.mesh, search_path, base_dir);
    spec.samples = c.required<std::vector<int64_t>>("samples", "an array of sample counts");
    if (spec.samples.empty()) c.fail("samples", "expected at least one sample count, got []");
    for (int64_t n : spec.samples)
        if (n < 8) c.fail("samples", "expected sample counts of at least 8, got " + std::to_string(n));
    c.finish();
    return spec;
}

}  // namespace

std::vector<MeshCase> read_mesh_cases(JsonReader& config, const std::vector<std::string>& search_path,
                                      const std::string& base_dir) {
    std::vector<JsonReader> cases = config.objects("cases");
    if (cases.empty()) config.fail("cases", "expected at least one case, got []");
    std::vector<MeshCase> out;
    for (JsonReader& c : cases) out.push_back(read_mesh_case(c, search_path, base_dir));
    return out;
}

PreparedMesh load_case_mesh(const MeshCase& c, const std::vector<std::string>& search_path, const std::string& base_dir,
                            RunContext& ctx) {
    StudyInputs in;
    in.mesh = c.mesh;
    in.search_path = search_path;
    in.base_dir = base_dir;
    PreparedMesh mesh = load_prepared_mesh(in, *ctx.log);
    ctx.inputs["meshes"][c.label] = {{"source", mesh.source()}, {"sha256", mesh.content_sha256()}};
    return mesh;
}

}  // namespace sdf
