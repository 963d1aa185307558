#include "harness/sampling/point_query.h"

#include "harness/sampling/mesh_sdf.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {

std::vector<std::string> point_query_backends() {
    std::vector<std::string> names = {"auto"};
    for (const std::string& b : sampler_backends()) names.push_back(b);
    return names;
}

std::string resolve_backend(const std::string& backend) {
    if (backend != "auto") return backend;
    return cuda_backend_available() ? "cuda" : "cpu";
}

SamplerOptions point_query_sampler_options(const PointQueryOptions& options) {
    SamplerOptions s;
    s.backend = resolve_backend(options.backend);
    s.method = options.method;
    s.kernel = options.kernel;
    s.precision = options.precision;
    s.sign = options.sign;
    s.threads = options.threads;
    s.progress = options.progress;
    s.device = options.device;
    check_sampler_kernel(s);  // also checks the backend and the method against the table
    return s;
}

PointQueryResult query_points(const PreparedMesh& mesh, const std::vector<Vec3d>& points,
                              const PointQueryOptions& options) {
    // The caller owns the mesh for the call: the bound object borrows it.
    const MeshSdf sdf(std::shared_ptr<const PreparedMesh>(&mesh, [](const PreparedMesh*) {}),
                      point_query_sampler_options(options));
    PointQueryResult result;
    result.sampler = sdf.sampler_name();
    result.sign = sdf.sign_mode();
    result.samples = sdf.query(points);
    return result;
}

}  // namespace sdf
