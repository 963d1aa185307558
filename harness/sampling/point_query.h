/// @file point_query.h
/// @brief Exact signed distance, gradient and closest triangle of arbitrary points: the one
/// path that `sdf-query` and the Python module's `query()` take, so that both give the same
/// numbers to the last bit for the same options.
///
/// Backends and methods are the sampler table's (harness/sampling/sampler_table.h), plus the
/// backend "auto": cuda when this build has the CUDA backend and a GPU is present, else cpu.
/// The method defaults to "bvh" (about log n per point; "brute_force" on request).
#pragma once

#include <string>
#include <vector>

#include "core/sampling/sampler.h"

namespace sdf {

struct PointQueryOptions {
    std::string backend = "auto";  ///< "auto", or a backend of the sampler table
    std::string method = "bvh";    ///< a method of the sampler table
    std::string kernel;            ///< "" = the row's default kernel
    Precision precision = Precision::Float;
    SignMode sign = SignMode::Auto;
    int threads = 0;               ///< CPU threads; 0 = all
    bool progress = true;          ///< progress lines on stderr for long queries
    int device = 0;                ///< CUDA device
};

/// The backend names a query accepts: "auto" first, then the sampler table's.
std::vector<std::string> point_query_backends();

/// "cuda" or "cpu" for "auto", else `backend` unchanged.
std::string resolve_backend(const std::string& backend);

/// The sampler options of a query ("auto" resolved); throws std::invalid_argument for an
/// unknown backend, method or kernel, naming the alternatives (as the config parser does).
SamplerOptions point_query_sampler_options(const PointQueryOptions& options);

struct PointQueryResult {
    std::vector<PointSample> samples;  ///< in input order
    std::string sampler;               ///< the sampler's name, e.g. "cpu/bvh/brick"
    std::string sign;                  ///< the sign mode used, "pseudonormal" or "winding"
};

/// Queries every point through a MeshSdf bound for this call (mesh_sdf.h: hold one to
/// query a mesh many times); throws std::runtime_error when the chosen backend cannot run here.
PointQueryResult query_points(const PreparedMesh& mesh, const std::vector<Vec3d>& points,
                              const PointQueryOptions& options);

}  // namespace sdf
