/// @file sampler.h
/// @brief The interface every sampling backend implements (CPU threads, CUDA); the options
/// that select one are core/sampling/sampler_options.h. A sampler knows a PreparedMesh and a
/// Lattice, never a config.
///
/// Build once, query many times (as fcpw's Scene::build() and NanoVDB's MeshToGrid): a
/// Sampler holds only its options; bind(mesh) makes a BoundSampler that owns every per-mesh
/// structure the queries need (the BVH through the mesh, the sign's winding data, on the GPU
/// the device uploads and trees), built there and nowhere else. Its queries are const and
/// take no mesh, so nothing is kept per call or compared by identity.
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
#include "core/sampling/sparse_band.h"
#include "core/sampling/stored_slab.h"
#include "core/winding/winding_sign.h"
#include "kernels/lattice/lattice_slab.h"
#include "kernels/lattice/sampling_grid.h"

namespace sdf {

/// Result for one arbitrary query point.
struct PointSample {
    double distance = 0;
    Vec3d gradient{};
    int32_t triangle = -1;  ///< 0-based, in the mesh file's face order
};

/// A sampler bound to its mesh (Sampler::bind). Every query is const; a backend that keeps
/// device scratch buffers between calls serialises its calls inside.
class BoundSampler {
public:
    virtual ~BoundSampler() = default;
    BoundSampler(const BoundSampler&) = delete;
    BoundSampler& operator=(const BoundSampler&) = delete;

    /// e.g. "cpu/brute_force/vectorized"
    virtual std::string name() const = 0;
    const PreparedMesh& mesh() const { return *mesh_; }
    const std::shared_ptr<const PreparedMesh>& shared_mesh() const { return mesh_; }
    /// The sign mode resolved for the mesh at binding (auto: choose_sign_mode on its report).
    virtual const SignModeChoice& sign() const = 0;

    /// Samples every point of the lattice.
    SampledField sample(const Lattice& lattice) const { return sample_slab(lattice, whole_lattice_slab(lattice)); }
    /// Samples one slab of the lattice (kernels/lattice/lattice_slab.h): the field's arrays
    /// hold the slab's points only, in its compact order (the whole lattice: every point in
    /// storage order). A distributed run gives each rank its slabs (harness/distributed).
    virtual SampledField sample_slab(const Lattice& lattice, const LatticeSlab& slab) const = 0;
    /// The same slab as a field file stores it (core/sampling/stored_slab.h), for samplers
    /// that produce the stored bytes where they compute (the CUDA BVH sampler, on the
    /// device); nullopt from the others, whose callers then use sample_slab(). The samples
    /// are sample_slab()'s with the narrow band of SamplerOptions::band_width applied.
    virtual std::optional<StoredSlab> sample_slab_stored(const Lattice& lattice, const LatticeSlab& slab,
                                                         const StoredLayout& layout) const {
        (void)lattice, (void)slab, (void)layout;
        return std::nullopt;
    }
    /// The narrow band of width `width` > 0 of the lattice, sparse (core/sampling/sparse_band.h,
    /// issue 35): densified, it is sample()'s field with SamplerOptions::band_width = width,
    /// byte for byte. The backends (BackendSampler) sample only the band's blocks with their
    /// point kernels (core/sampling/sparse_band_sampler.h); this default samples the whole
    /// lattice and sparsifies it (refused when the sampler's own band is narrower). The band
    /// holds `channels` (without the gradient: neither kept nor, on a GPU, downloaded); its
    /// distances and closest triangles are the same bytes either way.
    virtual SparseBandField sample_band_sparse(const Lattice& lattice, double width, BandChannels channels = {}) const;
    /// Samples arbitrary points, returned in input order. `timings` (may be null) receives
    /// this call's timings where the sampler measures them (GPU: `kernel` = the device's
    /// sort, search and finalize, `upload`/`download` the transfers; every sampler: the
    /// certificate's counts and `total`).
    virtual std::vector<PointSample> query(const std::vector<Vec3d>& points, SamplingTimings* timings = nullptr) const = 0;
    /// Samples points that are in GPU memory, writing the results there (core/sampling/
    /// device_query.h); false from samplers that do not run on a GPU. The numbers equal
    /// query()'s for the same points. Returns when the results are written (and the caller's
    /// stream may use them).
    virtual bool query_device(const DevicePoints& points, const DeviceQueryResults& results,
                              SamplingTimings* timings = nullptr) const {
        (void)points, (void)results, (void)timings;
        return false;
    }
    /// Samples points in the caller's host arrays, writing the results into its columns in
    /// input order (core/sampling/host_query.h): query()'s numbers, with no conversion by the
    /// caller. This default gathers the points and calls query(); GPU samplers stream the
    /// caller's bytes through pinned buffers instead, the CPU BVH reads them in place. Throws std::invalid_argument for a
    /// point that is not finite (naming its row) or out of the search's range.
    virtual void query_host(const HostPoints& points, const HostQueryResults& results,
                            SamplingTimings* timings = nullptr) const {
        scatter_samples(query(gather_points(points, "points", 0), timings), results, 0);
    }

protected:
    explicit BoundSampler(std::shared_ptr<const PreparedMesh> mesh);

private:
    std::shared_ptr<const PreparedMesh> mesh_;
};

/// A sampler's options and kernel, not yet bound to a mesh.
class Sampler {
public:
    virtual ~Sampler() = default;
    /// e.g. "cpu/brute_force/vectorized"
    virtual std::string name() const = 0;
    /// Builds everything the queries of `mesh` need (its BVH, the sign's winding data, the
    /// device uploads) and returns the sampler bound to it, which shares the mesh's
    /// ownership. Throws std::invalid_argument for a null mesh.
    virtual std::unique_ptr<BoundSampler> bind(std::shared_ptr<const PreparedMesh> mesh) const = 0;
};

/// bind() then sample(): for a caller that samples a mesh once (tests, one-off tools).
SampledField sample_once(const Sampler& sampler, std::shared_ptr<const PreparedMesh> mesh, const Lattice& lattice);
/// bind() then query().
std::vector<PointSample> query_once(const Sampler& sampler, std::shared_ptr<const PreparedMesh> mesh,
                                    const std::vector<Vec3d>& points, SamplingTimings* timings = nullptr);

}  // namespace sdf
