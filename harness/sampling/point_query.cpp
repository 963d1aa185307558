#include "harness/sampling/point_query.h"

#include "harness/sampling/mesh_sdf.h"
#include "harness/sampling/sampler_table.h"

namespace sdf {

std::vector<std::string> point_query_backends() { return sampler_backend_choices(); }

SamplerOptions point_query_sampler_options(const PointQueryOptions& options) {
    SamplerOptions s = options;
    s.backend = resolve_sampler_backend(options.backend);
    check_sampler_kernel(s);  // also checks the backend and the method against the table
    return s;
}

PointQueryResult query_points(std::shared_ptr<const PreparedMesh> mesh, const std::vector<Vec3d>& points,
                              const PointQueryOptions& options) {
    const MeshSdf sdf(std::move(mesh), point_query_sampler_options(options));
    PointQueryResult result;
    result.sampler = sdf.sampler_name();
    result.sign = sdf.sign_mode();
    result.samples = sdf.query(points);
    return result;
}

}  // namespace sdf
