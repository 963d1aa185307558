#include "harness/sampling/sparse_band_slabs.h"

#include <stdexcept>
#include <utility>

#include "core/sampling/narrow_band.h"

namespace sdf {

SparseBandSlabs::SparseBandSlabs(const BoundSampler& sampler, SparseBandField band)
    : BoundSampler(sampler.shared_mesh()), sampler_(sampler), band_(std::move(band)) {}

SampledField SparseBandSlabs::sample_slab(const Lattice& lattice, const LatticeSlab& slab) const {
    const Lattice& own = band_.lattice;
    if (lattice.type != own.type || !(lattice.resolution == own.resolution) || lattice.spacing != own.spacing ||
        lattice.origin.x != own.origin.x || lattice.origin.y != own.origin.y || lattice.origin.z != own.origin.z)
        throw std::invalid_argument("sparse band slabs: asked for a slab of another lattice than the band's");
    NarrowBandCounts counts;  // from the band's mask: the field may hold no triangles
    SampledField field = band_.densify_slab(slab, &counts);
    field.sampler = band_.sampler;
    if (field.sampler.band) {
        field.sampler.band->points_in_band = counts.in_band;
        field.sampler.band->points_outside = counts.outside;
    }
    if (slab.z_begin != 0) {  // the band's sampling is counted once, with the first slab
        field.sampler.points_computed = 0;
    } else {
        field.timings = band_.timings;
    }
    field.mesh = band_.mesh;
    return field;
}

}  // namespace sdf
