/// @file sparse_band_slabs.h
/// @brief A sparse narrow band (core/sampling/sparse_band.h) served slab by slab as a bound
/// sampler, so that sdf-sample's streamed writer (streamed_sampling.h) writes the dense field
/// file (and its .vdb) from it under the memory budget, without the whole lattice in memory.
/// Point queries go to the sampler that made the band.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/sampling/sampler.h"
#include "core/sampling/sparse_band.h"

namespace sdf {

class SparseBandSlabs final : public BoundSampler {
public:
    /// `sampler` made `band`; it must outlive this object.
    SparseBandSlabs(const BoundSampler& sampler, SparseBandField band);

    std::string name() const override { return sampler_.name(); }
    const SignModeChoice& sign() const override { return sampler_.sign(); }
    /// The slab's points of the band, densified. Its report holds the slab's band counts; the
    /// first slab (z_begin 0) also carries the band's sampling (points computed, timings,
    /// details), so that merging every slab's report gives the band's.
    SampledField sample_slab(const Lattice& lattice, const LatticeSlab& slab) const override;
    std::vector<PointSample> query(const std::vector<Vec3d>& points, SamplingTimings* timings = nullptr) const override {
        return sampler_.query(points, timings);
    }
    const SparseBandField& band() const { return band_; }

private:
    const BoundSampler& sampler_;
    SparseBandField band_;
};

}  // namespace sdf
