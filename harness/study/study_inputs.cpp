#include "harness/study/study_inputs.h"

#include <iostream>

#include "harness/build_config.h"
#include "harness/config/sampler_spec.h"
#include "harness/distributed/distributed.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {

std::vector<std::string> read_search_path(JsonReader& config, const RunContext& context) {
    const auto data_path = config.optional<std::vector<std::string>>("data_path", {}, "an array of directories");
    return data_search_path(data_path, context.config_dir);
}

double read_domain_margin(JsonReader& config) {
    JsonReader domain = config.optional_object("domain");
    const double margin = domain.optional<double>("margin", 0.1, "a margin as a fraction of the mesh's largest extent");
    if (!(margin >= 0)) domain.fail("margin", "expected a non-negative fraction, got " + domain.raw("margin").dump());
    domain.finish();
    return margin;
}

void require_backend(const SamplerOptions& options, const JsonReader& config, const std::string& key) {
    if (sampler_kind(options).on_gpu && !cuda_backend_available())
        config.fail(key + ".backend", std::string("\"cuda\" is not available here: ") +
                                          (SDF_HAVE_CUDA ? "no CUDA device is present"
                                                               : "this build has no CUDA backend") +
                                          " (use \"cpu\", or \"auto\" to take the GPU when there is one)");
}

StudyInputs read_study_inputs(JsonReader& config, const RunContext& context, bool lattices_required) {
    StudyInputs in;
    in.mesh = parse_mesh_spec(config, "mesh");
    in.search_path = read_search_path(config, context);
    in.base_dir = context.config_dir;
    resolve_mesh_file(in.mesh, in.search_path, in.base_dir);
    in.margin = read_domain_margin(config);
    if (lattices_required || config.has("lattices")) {
        std::vector<JsonReader> lattices = config.objects("lattices");
        if (lattices.empty()) config.fail("lattices", "expected at least one lattice, got []");
        for (JsonReader& l : lattices) {
            in.lattices.push_back(parse_lattice_spec(l));
            l.finish();
        }
        in.lattice_labels = lattice_spec_labels(in.lattices, config);
    }
    JsonReader s = config.optional_object("sampler");
    in.sampler = parse_sampler_options(s);
    require_backend(in.sampler, config, "sampler");
    return in;
}

PreparedMesh load_prepared_mesh(const StudyInputs& inputs, std::ostream& log) {
    const PreparedMesh mesh = [&] {
        try {
            const TriangleMesh loaded = load_mesh(inputs.mesh, inputs.search_path, inputs.base_dir);
            share_mesh_with_workers(loaded);  // a distributed run's workers prepare it too
            return prepare_mesh(loaded);
        } catch (const ConfigError&) {
            throw;  // already names the config file and key
        } catch (const std::exception& e) {
            throw std::runtime_error(inputs.mesh.config_file + ": key '" + inputs.mesh.key_path + "': " + e.what());
        }
    }();
    const MeshReport& r = mesh.report();
    log << "mesh " << mesh.name() << " (" << mesh.source() << "): " << mesh.vertices().size() << " vertices, "
        << mesh.triangles().size() << " triangles, " << r.components << " component(s), "
        << (r.closed() ? "closed" : "open") << (r.consistently_oriented() ? ", consistently oriented" : ", INCONSISTENT orientation")
        << "\n";
    for (const std::string& w : mesh.warnings()) std::cerr << "warning: " << w << "\n";
    return mesh;
}

std::string with_commas(int64_t v) {
    std::string s = std::to_string(v < 0 ? -v : v);
    for (int i = int(s.size()) - 3; i > 0; i -= 3) s.insert(size_t(i), ",");
    return v < 0 ? "-" + s : s;
}

}  // namespace sdf

namespace sdf {

MemoryNeed lattice_memory_need(const StudyInputs& in, uint64_t bytes_per_point, bool all_at_once, const std::string& step) {
    MemoryNeed need;
    uint64_t points = 0;  // per-spec counts fit in int64 (parse_lattice_spec checks them)
    std::string which;
    for (size_t i = 0; i < in.lattices.size(); ++i) {
        Lattice l;
        l.type = in.lattices[i].type;
        l.resolution = lattice_spec_resolution(in.lattices[i]);
        const uint64_t n = uint64_t(l.num_points());
        if (all_at_once) {
            points += n;
        } else if (n > points) {
            points = n;
            which = " " + lattice_spec_notation(in.lattices[i]);
        }
    }
    // Saturate instead of wrapping: a lattice of 2^60 points "needs" more than any machine has.
    const uint64_t per_point = points > (UINT64_MAX - kBaseBytes) / bytes_per_point ? UINT64_MAX - kBaseBytes
                                                                                     : points * bytes_per_point;
    need.host_bytes = kBaseBytes + per_point;
    need.what = step + which + " (" + with_commas(int64_t(points)) + " points" + (all_at_once ? " in all" : "") + ")";
    return need;
}

}  // namespace sdf
