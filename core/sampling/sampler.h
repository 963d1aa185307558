/// @file sampler.h
/// @brief The interface every sampling backend implements (CPU threads, CUDA); the options
/// that select one are core/sampling/sampler_options.h. A sampler knows a PreparedMesh and a
/// Lattice, never a config.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh/prepared_mesh.h"
#include "core/sampling/device_query.h"
#include "core/sampling/host_query.h"
#include "core/sampling/sampled_field.h"
#include "core/sampling/sampler_options.h"
#include "core/sampling/stored_slab.h"
#include "core/winding/sign_mode.h"
#include "kernels/lattice/lattice_slab.h"
#include "kernels/lattice/sampling_grid.h"

namespace sdf {

/// Result for one arbitrary query point.
struct PointSample {
    double distance = 0;
    Vec3d gradient{};
    int32_t triangle = -1;  ///< 0-based, in the mesh file's face order
};

class Sampler {
public:
    virtual ~Sampler() = default;
    /// e.g. "cpu/brute_force/vectorized"
    virtual std::string name() const = 0;
    /// Samples every point of the lattice.
    SampledField sample(const PreparedMesh& mesh, const Lattice& lattice) {
        return sample_slab(mesh, lattice, whole_lattice_slab(lattice));
    }
    /// Samples one slab of the lattice (kernels/lattice/lattice_slab.h): the field's arrays
    /// hold the slab's points only, in its compact order (the whole lattice: every point in
    /// storage order). A distributed run gives each rank its slabs (harness/distributed).
    virtual SampledField sample_slab(const PreparedMesh& mesh, const Lattice& lattice, const LatticeSlab& slab) = 0;
    /// The same slab as a field file stores it (core/sampling/stored_slab.h), for samplers
    /// that produce the stored bytes where they compute (the CUDA BVH sampler, on the
    /// device); nullopt from the others, whose callers then use sample_slab(). The samples
    /// are sample_slab()'s with the narrow band of SamplerOptions::band_width applied.
    virtual std::optional<StoredSlab> sample_slab_stored(const PreparedMesh& mesh, const Lattice& lattice,
                                                         const LatticeSlab& slab, const StoredLayout& layout) {
        (void)mesh, (void)lattice, (void)slab, (void)layout;
        return std::nullopt;
    }
    /// Samples arbitrary points, returned in input order.
    virtual std::vector<PointSample> query(const PreparedMesh& mesh, const std::vector<Vec3d>& points) = 0;
    /// Samples points that are in GPU memory, writing the results there (core/sampling/
    /// device_query.h); false from samplers that do not run on a GPU. The numbers equal
    /// query()'s for the same points. Returns when the results are written (and the caller's
    /// stream may use them).
    virtual bool query_device(const PreparedMesh& mesh, const DevicePoints& points, const DeviceQueryResults& results) {
        (void)mesh, (void)points, (void)results;
        return false;
    }
    /// Samples points in the caller's host arrays, writing the results into its columns in
    /// input order (core/sampling/host_query.h): query()'s numbers, with no conversion by the
    /// caller. This default gathers the points and calls query(); GPU samplers stream the
    /// caller's bytes through pinned buffers instead. Throws std::invalid_argument for a
    /// point that is not finite (naming its row) or out of the search's range.
    virtual void query_host(const PreparedMesh& mesh, const HostPoints& points, const HostQueryResults& results) {
        scatter_samples(query(mesh, gather_points(points, "points", 0)), results, 0);
    }
    /// The timings of the last query() where the sampler measures them (GPU: `kernel` = the
    /// device's sort, search and finalize, `upload`/`download` the transfers); else zeros.
    const SamplingTimings& last_query_timings() const { return query_timings_; }

protected:
    SamplingTimings query_timings_;
};

}  // namespace sdf
