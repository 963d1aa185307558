/// @file sampler_results.h
/// @brief What every sampler (CPU and CUDA, brute force and BVH) does with its results:
/// each is stored at its lattice index or query position, its triangle renumbered from the
/// prepared mesh to the mesh file's face order, and the provenance keys they all share are
/// recorded the same way.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mesh/prepared_mesh.h"
#include "core/parallel/parallel_for.h"
#include "core/sampling/sampled_field.h"
#include "core/sampling/sampler.h"
#include "core/sampling/sampler_sign.h"
#include "core/sampling/search_range.h"

namespace sdf {

/// A field for the points of one slab of `lattice` (compact: its primary, then secondary
/// planes; the whole lattice is one slab), every point unset (distance 0, triangle -1), to be
/// filled; throws first when the mesh or the lattice is beyond what the search answers
/// (search_range.h).
inline SampledField unfilled_field(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab,
                                   Precision precision) {
    require_search_range(mesh, lattice, precision);
    SampledField field;
    field.lattice = lattice;
    field.precision = precision;
    field.resize(slab_point_count(lattice, slab));
    return field;
}

/// Stores one result at lattice index `out`; `triangle` indexes `mesh`'s prepared triangles.
inline void store_sample(SampledField& field, int64_t out, const PreparedMesh& mesh, double distance,
                         const Vec3d& gradient, int32_t triangle) {
    field.distance[size_t(out)] = distance;
    field.gradient[size_t(out)] = gradient;
    field.closest_triangle[size_t(out)] = triangle < 0 ? triangle : mesh.source_triangle()[size_t(triangle)];  // < 0: no triangle (narrow band)
}

/// The result of one query point; `triangle` indexes `mesh`'s prepared triangles.
inline PointSample point_sample(const PreparedMesh& mesh, double distance, const Vec3d& gradient, int32_t triangle) {
    return {distance, gradient, triangle < 0 ? triangle : mesh.source_triangle()[size_t(triangle)]};
}

/// `n` unset query results (distance 0, triangle -1) to be filled on `threads` threads
/// (0: all cores). The vector's storage is first touched a page at a time on every thread,
/// then written once (40 bytes a point) on this one: a million-point query's 10,000 page
/// faults were 20-25 ms on the calling thread, more than its Morton sort on 16.
inline std::vector<PointSample> unfilled_point_samples(size_t n, int threads) {
    std::vector<PointSample> out;
    out.reserve(n);
    constexpr size_t kPage = 4096;
    unsigned char* storage = reinterpret_cast<unsigned char*>(out.data());
    const size_t bytes = n * sizeof(PointSample), pages = (bytes + kPage - 1) / kPage;
    parallel_for(int64_t(pages), 256, threads, [&](int64_t begin, int64_t end) {
        for (int64_t page = begin; page < end; ++page) storage[size_t(page) * kPage] = 0;
    });
    out.resize(n);
    return out;
}

/// Scatters a batch of results (per point: distance, gradient, triangle, output_index) into
/// a field. A negative output_index has no destination: a padding thread, or a point of
/// BCC strategy A's double-resolution grid that is not a BCC point.
template <typename Batch>
void scatter_batch(const Batch& batch, const PreparedMesh& mesh, SampledField& field) {
    for (size_t i = 0; i < batch.output_index.size(); ++i)
        if (batch.output_index[i] >= 0)
            store_sample(field, batch.output_index[i], mesh, batch.distance[i], batch.gradient[i], batch.triangle[i]);
}

/// The same into the results of a point list (output_index = position in the list).
template <typename Batch>
void scatter_batch(const Batch& batch, const PreparedMesh& mesh, std::vector<PointSample>& points) {
    for (size_t i = 0; i < batch.output_index.size(); ++i)
        if (batch.output_index[i] >= 0)
            points[size_t(batch.output_index[i])] = point_sample(mesh, batch.distance[i], batch.gradient[i], batch.triangle[i]);
}

/// The report every sampler records in SampledField::sampler: backend, method, kernel,
/// precision, points computed, and as details "sign" (the requested and resolved sign mode
/// and why: SamplerSign::provenance()), "bcc_strategy" on a BCC lattice and "band_width" in a
/// band. Each sampler adds its band and certificate counts and its own details (threads,
/// plan, bvh, device).
SamplerReport sampler_provenance(const std::string& backend, const std::string& method, const std::string& kernel,
                                  const SamplerOptions& options, const Lattice& lattice, int64_t points_computed,
                                  const SamplerSign& sign);

}  // namespace sdf
