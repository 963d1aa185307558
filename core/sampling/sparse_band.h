/// @file sparse_band.h
/// @brief A narrow band stored sparsely (issue 35): the lattice in blocks of 8^3 points (as
/// OpenVDB's leaves), the exact values of the active blocks only, and the outside as signs.
///
/// Layout. A lattice is its cosets (kernels/lattice/lattice_kinds.h: CC one grid, BCC its
/// primary grid and its secondary grid shifted by h/2), each a CC grid cut into blocks of
/// 8 x 8 x 8 points: coset point (i, j, k) lies in block (i, j, k) / 8 at local index
/// (i % 8) + 8 (j % 8) + 64 (k % 8) (x fastest, as OpenVDB's leaf offsets run z fastest: a
/// writer transposes). Blocks are numbered coset by coset, x fastest then y then z, and a
/// block's id is that number (BandLayout::block_id); ids sort as the lattice's storage does.
/// A block's cell is the box from its first point to 8 spacings beyond it on every axis: the
/// cells of a coset tile space, so a cell that meets no triangle holds one side of the surface.
///
/// Values. Every point of an active block (sorted in `active`) holds what the dense banded
/// field holds there (narrow_band.h): exact distance, gradient and closest triangle where
/// |d| <= W, else +-W, gradient 0 and kOutsideBandTriangle. Points of a block beyond the
/// coset's resolution (the last blocks of each axis) are padding: +W, gradient 0,
/// kOutsideBandTriangle, and no lattice point (BandLayout::storage_index is -1).
/// The band's points (|d| <= W: the dense field's points with exact values) are marked in
/// `band_mask`, one bit per point of each active block (padding bits clear): every reader of
/// band membership (counts, level sets' active voxels, the band's cells) reads it there.
/// The gradient and the closest triangle are held only when asked (BandChannels): a point
/// costs 8 bytes of distance and 1/8 byte of mask, +24 with the gradient, +4 with the triangle
/// (36.125 with both, as sampled by default; 8.125 with the distance alone); a band sampled
/// for float32 outputs only holds its distances in float32 (band_distances.h: 4 bytes).
/// Every other block is outside the band: a tile of one sign (bit `inside_tiles`: -W, else
/// +W), or, where its points' signs differ (the winding sign across a hole, far from any
/// triangle), a "mixed" block whose signs are stored per point (512 bits).
///
/// As a level set: coset c is an OpenVDB/NanoVDB grid of index-space voxels (i, j, k) with
/// the transform world = lattice.origin + (h/2) first(c) + h (i, j, k) (first: (0,0,0), BCC
/// secondary (1,1,1)); active blocks are leaves (active voxels: the band's points, set bits
/// of band_mask), inside tiles are tiles of value -W, everything
/// else background +W; a mixed block is a leaf with every voxel inactive at +-W.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/default_init_vector.h"
#include "core/sampling/band_distances.h"
#include "core/sampling/narrow_band.h"
#include "core/sampling/sampled_field.h"
#include "kernels/lattice/band_blocks.h"
#include "kernels/lattice/lattice_slab.h"

namespace sdf {

/// The blocks of a lattice (see the file's comment): the lattice and its BandBlockGrid
/// (kernels/lattice/band_blocks.h, the mapping the device kernels share).
class BandLayout {
public:
    BandLayout() = default;
    explicit BandLayout(const Lattice& lattice) : lattice_(lattice), grid_(BandBlockGrid::of(lattice)) {}

    const Lattice& lattice() const { return lattice_; }
    const BandBlockGrid& grid() const { return grid_; }
    int cosets() const { return grid_.cosets; }
    const BandCoset& coset(int c) const { return grid_.coset[c]; }
    /// Blocks of every coset together.
    int64_t block_count() const { return grid_.block_count; }

    int64_t block_id(int coset, const Int3& block) const { return grid_.block_id(coset, block); }
    BandBlockCoords block_coords(int64_t id) const { return grid_.block_coords(id); }
    /// Coset point (i, j, k) of block-local index `local` (0 .. 511, x fastest).
    static Int3 local_offset(int local) { return BandBlockGrid::local_offset(local); }
    /// The coset's point indices (i, j, k) of point `local` of block `id`.
    Int3 coset_point(int64_t id, int local) const { return BandBlockGrid::coset_point(block_coords(id), local); }
    /// Integer coordinates (units of h/2, Lattice::position_of_coords) of that point.
    Int3 point_coords(int64_t id, int local) const { return grid_.point_coords(block_coords(id), local); }
    /// Its lattice storage index, or -1 for padding (beyond the coset's resolution).
    int64_t storage_index(int64_t id, int local) const { return grid_.storage_index(block_coords(id), local); }
    /// The block's lattice points per axis (BandBlockGrid::block_points): point `local` is one
    /// iff BandBlockGrid::within(block_points(b), local).
    Int3 block_points(const BandBlockCoords& b) const { return grid_.block_points(b); }
    /// The block's cell (see the file's comment), in world units.
    void cell_box(int64_t id, Vec3d& lo, Vec3d& hi) const;

private:
    Lattice lattice_{};
    BandBlockGrid grid_{};
};

/// One bit per point of a block: bit (local & 63) of word (local >> 6), local the point's
/// block-local index (x fastest). 64-bit words, so that a device writing it as 32-bit halves
/// on a little-endian host (bvh_band_blocks.cu) gives the same bytes.
using BandPointMask = std::array<uint64_t, kBandBlockPoints / 64>;
/// The sides of a mixed block (bit set: inside, -W).
using BandSignMask = BandPointMask;

inline bool mask_bit(const BandPointMask& m, int local) { return (m[size_t(local >> 6)] >> (local & 63)) & 1; }
inline void set_mask_bit(BandPointMask& m, int local) { m[size_t(local >> 6)] |= uint64_t(1) << (local & 63); }

/// What a sparse band holds, counted.
struct SparseBandCounts {
    int64_t blocks = 0;          ///< every block of the lattice
    int64_t active_blocks = 0;   ///< with values
    int64_t mixed_blocks = 0;    ///< outside the band, signs per point
    int64_t tiles = 0;           ///< outside the band, one sign (blocks - active - mixed)
    int64_t inside_tiles = 0;    ///< of them, inside (-W)
    int64_t active_points = 0;   ///< lattice points of the active blocks (padding not counted)
    int64_t band_points = 0;     ///< of them, |d| <= W (bits of band_mask)
};

/// The value channels a sparse band holds, as its sampler is asked for them. The distance
/// and the band's points (band_mask) are always held; without the closest triangle the
/// band's points are still known (the mask), not which triangle is nearest.
struct BandChannels {
    bool gradient = true;          ///< 24 bytes a point
    bool closest_triangle = true;  ///< 4 bytes a point
    /// The distances' type (band_distances.h): float32 for a band whose outputs all store
    /// float32 (4 bytes a point instead of 8; values rounded once, as those writers round).
    BandDistanceType distance_type = BandDistanceType::Float64;
};

/// A band's channels by name, as reports list them: "distance", then "gradient" and
/// "closest_triangle" where held.
nlohmann::json channel_names(BandChannels channels);

struct SparseBandField {
    SparseBandField() = default;
    /// An empty band of `lattice` (no active block, every block an outside tile).
    SparseBandField(const Lattice& lattice, double width, Precision precision, BandChannels channels = {});

    Lattice lattice;
    double width = 0;            ///< W > 0, mesh units
    Precision precision = Precision::Float;
    /// What it holds: `gradient` (`closest_triangle`) is empty without its channel (sampled
    /// without it, or read from a file without it), else as long as `distance`.
    BandChannels channels;

    /// Active block ids, ascending; block a's values are [a * 512, (a + 1) * 512) of each channel.
    /// The value arrays' resize(n) leaves new values unwritten (a block kernel writes them all).
    std::vector<int64_t> active;
    BandDistances distance;      ///< in channels.distance_type
    DefaultInitVector<Vec3d> gradient;
    DefaultInitVector<int32_t> closest_triangle;  ///< in the mesh file's face order; kOutsideBandTriangle outside the band
    /// The band's points, one mask per active block (always held): bit set where |d| <= W
    /// (closest_triangle != kOutsideBandTriangle, where held); padding bits clear.
    DefaultInitVector<BandPointMask> band_mask;

    /// One bit per block id: the tile's side (set: inside, -W); meaningful for tiles only.
    std::vector<uint64_t> inside_tiles;
    /// Mixed block ids, ascending, and their per-point sides.
    std::vector<int64_t> mixed;
    std::vector<BandSignMask> mixed_inside;

    SamplingTimings timings;
    SamplerReport sampler;   ///< how it was sampled; `band` holds the band's counts
    MeshProvenance mesh;

    const BandLayout& layout() const { return layout_; }
    /// Index of block `id` in `active` (-1: not active), and in `mixed`.
    int64_t find_active(int64_t id) const;
    int64_t find_mixed(int64_t id) const;
    bool tile_inside(int64_t id) const { return (inside_tiles[size_t(id >> 6)] >> (id & 63)) & 1; }
    /// Whether point `local` of active block a (its index in `active`) is a band point.
    bool in_band(size_t a, int local) const { return mask_bit(band_mask[a], local); }
    void set_tile_inside(int64_t id, bool inside);

    /// Appends an active block (ids must come in ascending order) with every point padding
    /// (+W, gradient 0 and kOutsideBandTriangle when held, no band point);
    /// returns its index in `active`.
    int64_t add_active(int64_t id);
    /// Sets band_mask from closest_triangle (held): for code that writes the triangles
    /// itself (a file's reader, tests). Padding bits stay clear whatever their triangles.
    void mask_from_triangles();
    /// Appends a mixed block (ascending ids), every point outside.
    int64_t add_mixed(int64_t id);

    /// Throws std::invalid_argument naming `what` when `wanted` asks for a channel the band
    /// does not hold, or for double distances (distance_type Float64) of a band that holds
    /// float32 ones, or when the arrays of a channel it holds (or band_mask) do not match its
    /// active blocks.
    void require_channels(BandChannels wanted, const std::string& what) const;

    SparseBandCounts counts() const;
    /// Bytes held by the arrays (capacity, not size).
    size_t memory_bytes() const;

    /// The dense banded field this band stands for: every lattice point, in storage order,
    /// as a dense sampler with SamplerOptions::band_width = W stores it (provenance copied).
    /// Without the band's gradient (closest triangle) channel the field has none (an empty
    /// `gradient` / `closest_triangle`, as read_field gives a file without one). Throws
    /// std::length_error naming the size when the lattice has more than `max_points`.
    SampledField densify(int64_t max_points = INT64_MAX) const;
    /// The same for one slab of the lattice (kernels/lattice/lattice_slab.h), in the slab's
    /// compact order (sample_slab()'s): a dense field file written slab by slab under a
    /// memory budget, without the whole lattice in memory. Provenance not copied. `counts`
    /// (may be null) receives the slab's points in and outside the band (from band_mask:
    /// count_narrow_band() of a field without triangles cannot tell).
    SampledField densify_slab(const LatticeSlab& slab, NarrowBandCounts* counts = nullptr) const;
    /// Bytes densify() allocates for a lattice (distance, and the channels held).
    static int64_t dense_bytes(const Lattice& lattice, BandChannels channels = {});

    /// The sparse form of a dense banded field (SamplerOptions::band_width = W, or exact
    /// values, banded here): a block is active when one of its points is within the band,
    /// else a tile or a mixed block. The fallback of samplers without a sparse path. A channel
    /// asked of a field without it is refused (std::invalid_argument).
    static SparseBandField sparsify(const SampledField& field, double width, BandChannels channels = {});

private:
    BandLayout layout_;
};

}  // namespace sdf
