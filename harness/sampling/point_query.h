/// @file point_query.h
/// @brief Exact signed distance, gradient and closest triangle of arbitrary points: the one
/// path that `sdf-query` and the Python module's `query()` take, so that both give the same
/// numbers to the last bit for the same options.
///
/// A query takes the sampler's own options (core/sampling/sampler_options.h: the exact BVH on
/// the backend "auto" unless others are named); its lattice-only fields (BCC strategy,
/// narrow band) do not apply to points.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/sampling/sampler.h"

namespace sdf {

/// The options of a query are the sampler's (one type, one codec: harness/config/sampler_spec.h).
using PointQueryOptions = SamplerOptions;

/// The backend names a query accepts: "auto" first, then the sampler table's
/// (sampler_backend_choices(), harness/sampling/sampler_table.h).
std::vector<std::string> point_query_backends();

/// The sampler options of a query ("auto" resolved by resolve_sampler_backend); throws
/// std::invalid_argument for an unknown backend, method or kernel, naming the alternatives
/// (as the config parser does).
SamplerOptions point_query_sampler_options(const PointQueryOptions& options);

struct PointQueryResult {
    std::vector<PointSample> samples;  ///< in input order
    std::string sampler;               ///< the sampler's name, e.g. "cpu/bvh/brick"
    std::string sign;                  ///< the sign mode used, "pseudonormal" or "winding"
};

/// Queries every point through a MeshSdf bound for this call (mesh_sdf.h: hold one to
/// query a mesh many times); throws std::runtime_error when the chosen backend cannot run here.
PointQueryResult query_points(std::shared_ptr<const PreparedMesh> mesh, const std::vector<Vec3d>& points,
                              const PointQueryOptions& options);

}  // namespace sdf
