/// @file backend_sampler.h
/// @brief The steps every backend's bound sampler shares (CPU and CUDA, brute force and
/// BVH), written once: the sign resolved at binding (SamplerSign), the range checks, the
/// slab's sampling blocks, the timings, the certificate's counters, the certified winding
/// sign's counters, the narrow band's counts and the provenance (SamplerReport). A backend supplies its kernels through two
/// hooks: sample_blocks() fills a field from a slab's blocks, query_points() answers a
/// point list; what they did comes back in a SlabRun (or the query's timings).
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/sampling/certified_search.h"
#include "core/sampling/kernel_table.h"
#include "core/sampling/narrow_band.h"
#include "core/sampling/sampler.h"
#include "core/sampling/sampler_sign.h"
#include "core/sampling/sparse_band_sampler.h"

namespace sdf {

/// Calls f(T{}) with T the search's precision (float or double) and returns its result.
template <typename F>
decltype(auto) with_precision(Precision precision, F&& f) {
    if (precision == Precision::Float) return f(0.0f);
    return f(0.0);
}

/// One slab's sampling as a backend reports it to the shared steps.
struct SlabRun {
    SlabRun(const Lattice& lattice, const LatticeSlab& slab, BccStrategy strategy)
        : lattice(lattice), slab(slab), block_count(slab_sampling_blocks(lattice, strategy, slab, blocks)) {}
    SlabRun(const SlabRun&) = delete;
    SlabRun& operator=(const SlabRun&) = delete;

    const Lattice& lattice;
    const LatticeSlab& slab;
    /// The slab's sampling blocks (one per CC grid of the BCC strategy, sampling_grid.h).
    GridBlock blocks[kMaxSamplingBlocks];
    const int block_count;
    const GridBlock* begin() const { return blocks; }
    const GridBlock* end() const { return blocks + block_count; }
    const std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();

    int64_t computed = 0;             ///< points searched; pairs = computed x triangles (brute-force equivalent)
    CertificateCounters certificate;  ///< the float search's certificate (certified_search.h)
    SharedWindingCounts winding;      ///< winding sign: the points signed, by how their side was decided
    bool certified = true;            ///< false: a float search that keeps its own winner (thesis, Eberly)
    SamplingTimings device;           ///< upload, kernel, download; kernel 0: the run's wall time
    /// The narrow band: the kernels stored banded values (counted afterwards), or they stored
    /// exact ones everywhere and the band is applied to the field afterwards.
    bool band_applied = true;
    bool band_skips = false;          ///< bricks a probe proved outside the band were not searched
    std::optional<BandReport> skip_counts;  ///< the CPU brick skip's counts (probes, bricks and points skipped)
    nlohmann::json details = nlohmann::json::object();  ///< the backend's own (threads, plan, bvh, device)
};

class BackendSampler : public BoundSampler {
public:
    std::string name() const final { return std::string(backend_) + "/" + method_ + "/" + kernel_; }
    const SignModeChoice& sign() const final { return sign_.choice(); }

    /// The shared steps around sample_blocks(): band width checked, the slab's blocks, the
    /// timings, the provenance, the certificate and the band.
    SampledField sample_slab(const Lattice& lattice, const LatticeSlab& slab) const final;
    /// Only the band's blocks, through query_points() (sparse_band_sampler.h).
    SparseBandField sample_band_sparse(const Lattice& lattice, double width, BandChannels channels = {}) const override;
    /// The range checks around query_points(), and the call's timings.
    std::vector<PointSample> query(const std::vector<Vec3d>& points, SamplingTimings* timings = nullptr) const final;

protected:
    /// `kernel`: the kernel's name in the backend's table (core/sampling/kernel_table.h).
    BackendSampler(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, const char* backend,
                   const char* method, const char* kernel);

    /// Fills the field of `run`'s slab (unfilled_field(), sampler_results.h) block by block,
    /// adding to run's counters.
    virtual SampledField sample_blocks(SlabRun& run) const = 0;
    /// The samples of a non-empty point list in input order (range checked); `timings` takes
    /// what the backend measures, `certificate` the float search's counts.
    virtual std::vector<PointSample> query_points(const std::vector<Vec3d>& points, SamplingTimings& timings,
                                                  CertificateCounters& certificate) const = 0;

    /// The kernel that fills a sparse band's active blocks (sparse_band_sampler.h) as the
    /// backend's dense lattice kernel with a band of `width` fills those points; empty: the
    /// shared path queries their points with query_points().
    virtual BandBlockKernel band_block_kernel(double width) const {
        (void)width;
        return {};
    }

    /// The shared ending of a slab (also of a slab stored by the backend: `field` then holds
    /// no arrays and `band` its counts): timings, provenance, certificate, winding counters, band.
    void finish_slab(SampledField& field, SlabRun& run, std::optional<NarrowBandCounts> band = std::nullopt) const;

    const SamplerOptions& options() const { return options_; }
    bool float_search() const { return options_.precision == Precision::Float; }
    /// The mesh is the solid whose pseudonormal sign is one side per ball off its surface
    /// (choose_sign_mode's conditions under auto): the band's probes may sign what they skip.
    bool solid() const { return solid_; }
    /// A band's bricks may be skipped: each skipped point's sign is known (winding, or solid).
    bool band_skips_possible() const { return sign_.winding() || solid_; }

    SamplerOptions options_;
    /// Resolved by the backend's binding: prepare() (host winding sign) or prepare_mode().
    SamplerSign sign_;

private:
    const char* backend_;
    const char* method_;
    const char* kernel_;
    bool solid_ = false;
};

/// The unbound half of every backend: its options and its kernel, parsed with the backend's
/// kernel table (kernel_table.h) when it is made, so that a bad name fails before any mesh;
/// bind() makes the backend's `Bound` (a BackendSampler) for a mesh.
template <typename Bound, typename Kernel>
class BackendFactory final : public Sampler {
public:
    /// `what` names the sampler in a bad kernel name's message ("CPU BVH", ...).
    template <size_t N>
    BackendFactory(const SamplerOptions& options, const char* backend, const char* method,
                   const NamedKernel<Kernel> (&table)[N], const std::string& what)
        : options_(options), kernel_(kernel_from_name(table, options.kernel, what)),
          name_(std::string(backend) + "/" + method + "/" + kernel_name(table, kernel_)) {}

    std::string name() const override { return name_; }
    std::unique_ptr<BoundSampler> bind(std::shared_ptr<const PreparedMesh> mesh) const override {
        return std::make_unique<Bound>(std::move(mesh), options_, kernel_);
    }

private:
    SamplerOptions options_;
    Kernel kernel_;
    std::string name_;
};

}  // namespace sdf
