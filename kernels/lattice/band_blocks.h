/// @file band_blocks.h
/// @brief The blocks of 8^3 points of a sparse narrow band (core/sampling/sparse_band.h), written
/// once for host and device: block ids, a block's coset and coordinates, and a block-local
/// point's lattice coordinates and storage index. BandLayout (host) and the CUDA band kernel
/// (cuda/bvh/bvh_band_blocks.cu) both map through this, so they agree on every point.
///
/// Coset point (i, j, k) lies in block (i, j, k) / 8 at local index (i % 8) + 8 (j % 8) +
/// 64 (k % 8); blocks are numbered coset by coset, x fastest then y then z.
#pragma once

#include <cstdint>

#include "kernels/lattice/lattice.h"
#include "kernels/lattice/lattice_kinds.h"

namespace sdf {

inline constexpr int kBandBlockLog2 = 3;
inline constexpr int kBandBlockDim = 1 << kBandBlockLog2;  ///< 8 points per axis
inline constexpr int kBandBlockPoints = kBandBlockDim * kBandBlockDim * kBandBlockDim;  ///< 512

/// One coset's grid of blocks.
struct BandCoset {
    Int3 first{};              ///< integer coordinates (units of h/2) of the coset's point (0, 0, 0)
    Int3 points{};             ///< the coset's points per axis
    Int3 blocks{};             ///< blocks per axis: ceil(points / 8)
    int64_t first_block = 0;   ///< id of the coset's block (0, 0, 0)
    int64_t storage_offset = 0;  ///< lattice storage index of the coset's point (0, 0, 0)
    SDF_CPU_GPU int64_t block_count() const { return int64_t(blocks.x) * blocks.y * blocks.z; }
};

/// A block's coset and block coordinates.
struct BandBlockCoords {
    int coset = 0;
    Int3 block{};
};

/// The block grid of a lattice: its cosets (CC one, BCC the primary grid and the secondary
/// grid shifted by h/2, kernels/lattice/lattice_kinds.h), each cut into blocks.
struct BandBlockGrid {
    int cosets = 0;
    BandCoset coset[kMaxLatticeCosets]{};
    int64_t block_count = 0;  ///< blocks of every coset together

    static SDF_CPU_GPU int blocks_for(int points) { return points > 0 ? (points + kBandBlockDim - 1) / kBandBlockDim : 0; }

    static SDF_CPU_GPU BandBlockGrid of(const Lattice& lattice) {
        BandBlockGrid g;
        g.cosets = lattice.secondary_count() > 0 ? 2 : 1;
        int64_t storage = 0;
        for (int c = 0; c < g.cosets; ++c) {
            BandCoset& s = g.coset[c];
            s.first = c == 0 ? Int3{0, 0, 0} : Int3{1, 1, 1};
            s.points = c == 0 ? lattice.resolution : lattice.secondary_resolution();
            s.blocks = {blocks_for(s.points.x), blocks_for(s.points.y), blocks_for(s.points.z)};
            s.first_block = g.block_count;
            s.storage_offset = storage;
            g.block_count += s.block_count();
            storage += int64_t(s.points.x) * s.points.y * s.points.z;
        }
        return g;
    }

    SDF_CPU_GPU int64_t block_id(int c, const Int3& block) const {
        const BandCoset& s = coset[c];
        return s.first_block + block.x + int64_t(s.blocks.x) * (block.y + int64_t(s.blocks.y) * block.z);
    }
    SDF_CPU_GPU BandBlockCoords block_coords(int64_t id) const {
        int c = 0;
        while (c + 1 < cosets && id >= coset[c + 1].first_block) ++c;
        const BandCoset& s = coset[c];
        const int64_t local = id - s.first_block;
        return {c, {int(local % s.blocks.x), int((local / s.blocks.x) % s.blocks.y), int(local / (int64_t(s.blocks.x) * s.blocks.y))}};
    }
    /// Coset point offset (0..7 per axis) of block-local index `local` (0 .. 511, x fastest).
    static SDF_CPU_GPU Int3 local_offset(int local) {
        return {local & (kBandBlockDim - 1), (local >> kBandBlockLog2) & (kBandBlockDim - 1), local >> (2 * kBandBlockLog2)};
    }
    /// The coset's point indices (i, j, k) of point `local` of block `b`.
    static SDF_CPU_GPU Int3 coset_point(const BandBlockCoords& b, int local) {
        const Int3 o = local_offset(local);
        return {b.block.x * kBandBlockDim + o.x, b.block.y * kBandBlockDim + o.y, b.block.z * kBandBlockDim + o.z};
    }
    /// Integer coordinates (units of h/2, Lattice::position_of_coords) of that point.
    SDF_CPU_GPU Int3 point_coords(const BandBlockCoords& b, int local) const {
        const Int3 p = coset_point(b, local);
        const Int3 f = coset[b.coset].first;
        return {f.x + 2 * p.x, f.y + 2 * p.y, f.z + 2 * p.z};
    }
    /// The block's lattice points per axis: 8, fewer at the coset's far edges. Point `local`
    /// is a lattice point iff within(points, local): one test per block instead of one
    /// storage_index() a point, for the loops that visit every point of many blocks.
    SDF_CPU_GPU Int3 block_points(const BandBlockCoords& b) const {
        const Int3 n = coset[b.coset].points;
        const auto along = [](int total, int block) {
            const int left = total - block * kBandBlockDim;
            return left < kBandBlockDim ? left : kBandBlockDim;
        };
        return {along(n.x, b.block.x), along(n.y, b.block.y), along(n.z, b.block.z)};
    }
    static SDF_CPU_GPU bool whole(const Int3& points) {
        return points.x == kBandBlockDim && points.y == kBandBlockDim && points.z == kBandBlockDim;
    }
    static SDF_CPU_GPU bool within(const Int3& points, int local) {
        const Int3 o = local_offset(local);
        return o.x < points.x && o.y < points.y && o.z < points.z;
    }
    /// Whether the point lies beyond the coset's resolution (padding: no lattice point).
    SDF_CPU_GPU bool padding(const BandBlockCoords& b, int local) const {
        const Int3 p = coset_point(b, local);
        const Int3 n = coset[b.coset].points;
        return p.x >= n.x || p.y >= n.y || p.z >= n.z;
    }
    /// Its lattice storage index, or -1 for padding.
    SDF_CPU_GPU int64_t storage_index(const BandBlockCoords& b, int local) const {
        const BandCoset& s = coset[b.coset];
        const Int3 p = coset_point(b, local);
        if (p.x >= s.points.x || p.y >= s.points.y || p.z >= s.points.z) return -1;
        return s.storage_offset + p.x + int64_t(s.points.x) * (p.y + int64_t(s.points.y) * p.z);
    }
};

}  // namespace sdf
