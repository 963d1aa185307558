/// @file volume_grids.h
/// @brief The CC grids a field is exported as (one for CC, the primary and the secondary
/// grid for BCC), shared by the volume format writers (volume_formats.cpp, vdb_file.cpp).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/sampling/sampled_field.h"

namespace sdf {

struct VolumeGrid {
    std::string part;    ///< "" for a CC field, "primary" or "secondary" for BCC
    Vec3d origin{};      ///< world position of the grid's point (0,0,0)
    double spacing = 1;  ///< h
    Int3 resolution{};   ///< points per axis
    int64_t first = 0;   ///< storage index of the grid's first point in the field
    int64_t count() const { return int64_t(resolution.x) * resolution.y * resolution.z; }
};

/// A CC field's one grid, or a BCC field's primary grid (at the origin) and secondary grid
/// (at origin + h/2, one point fewer per axis), in storage order.
std::vector<VolumeGrid> volume_grids(const Lattice& lattice);

/// OpenVDB writer (vdb_file.cpp, built when OpenVDB is found): grids "distance" and
/// "gradient" (CC) or "distance_primary", ..., "gradient_secondary" (BCC) into `path`.
void write_vdb_file(const SampledField& field, const std::string& path, double band_in_spacings);

/// The narrow-band grids of write_vdb_file built part by part, as a streamed field's slabs
/// arrive (harness/sampling/streamed_sampling.h): only points with |distance| < band (world
/// units; the background, signed by side) are stored, so its memory grows with the band's
/// points, not the lattice's. write_vdb_file is this builder fed the whole field. Without
/// OpenVDB the constructor throws.
class VdbNarrowBandBuilder {
public:
    VdbNarrowBandBuilder(const Lattice& lattice, double band, bool gradient);
    ~VdbNarrowBandBuilder();
    VdbNarrowBandBuilder(const VdbNarrowBandBuilder&) = delete;
    VdbNarrowBandBuilder& operator=(const VdbNarrowBandBuilder&) = delete;
    /// Adds points [from, from + count) of `part`, which are lattice storage indices
    /// [offset, offset + count). Not thread-safe: one caller at a time.
    void add(const SampledField& part, int64_t from, int64_t count, int64_t offset);
    /// Flood-fills the inactive voxels' signs and writes the grids to `path` (the caller
    /// writes to a temporary name and renames).
    void write(const std::string& path);
    int64_t active_points() const { return active_; }

private:
    struct Grids;
    std::unique_ptr<Grids> grids_;
    int64_t active_ = 0;
};

}  // namespace sdf
