/// @file point_pieces.h
/// @brief Which points a launch works on ("a piece"), for lattices and for point lists.
///
/// A piece maps piece-local ids i to a position and to the output slot the result goes to
/// (-1: computed but discarded, as BCC strategy A does; or padding, see block_local).
/// Lattices larger than GPU memory are processed as several pieces.
#pragma once

#include "kernels/distance/mesh_view.h"
#include "kernels/lattice/sampling_grid.h"

namespace sdf::cuda {

/// A contiguous range [begin, begin + count) of one GridBlock's points.
struct GridRangePiece {
    Lattice lattice;
    GridBlock block;
    int64_t begin = 0;
    int64_t count = 0;

    SDF_CPU_GPU int64_t size() const { return count; }
    SDF_CPU_GPU int64_t block_local(int64_t i) const { return begin + i; }
    SDF_CPU_GPU Vec3d position(int64_t i) const { return lattice.position_of_coords(block.coords(begin + i)); }
    SDF_CPU_GPU int64_t output_index(int64_t i) const { return block.output_index(lattice, begin + i); }
};

/// The thesis's layout (section 3.3): the block is padded to multiples of 32 and cut into
/// 32x32x32 regions; piece-local id i is region (first_region + i / 32768), thread i % 32768.
struct GridRegionPiece {
    static constexpr int kRegion = 32;
    static constexpr int kRegionPoints = kRegion * kRegion * kRegion;
    Lattice lattice;
    GridBlock block;
    Int3 regions{};          ///< regions per axis
    int64_t first_region = 0;
    int64_t region_count = 0;

    SDF_CPU_GPU int64_t size() const { return region_count * kRegionPoints; }
    /// Block-local point index, or -1 for padding beyond the block's resolution.
    SDF_CPU_GPU int64_t block_local(int64_t i) const {
        const int64_t region = first_region + i / kRegionPoints;
        const int id = int(i % kRegionPoints);
        const int rx = int(region % regions.x), ry = int((region / regions.x) % regions.y),
                  rz = int(region / (int64_t(regions.x) * regions.y));
        const int x = rx * kRegion + id % kRegion, y = ry * kRegion + (id / kRegion) % kRegion,
                  z = rz * kRegion + id / (kRegion * kRegion);
        const Int3 r = block.resolution;
        if (x >= r.x || y >= r.y || z >= r.z) return -1;
        return x + int64_t(r.x) * (y + int64_t(r.y) * z);
    }
    SDF_CPU_GPU Vec3d position(int64_t i) const {
        const int64_t local = block_local(i);
        return lattice.position_of_coords(block.coords(local < 0 ? 0 : local));
    }
    SDF_CPU_GPU int64_t output_index(int64_t i) const {
        const int64_t local = block_local(i);
        return local < 0 ? -1 : block.output_index(lattice, local);
    }
};

/// Arbitrary query points [begin, begin + count) of a list already on the device.
struct PointListPiece {
    const Vec3d* points = nullptr;
    int64_t begin = 0;
    int64_t count = 0;

    SDF_CPU_GPU int64_t size() const { return count; }
    SDF_CPU_GPU int64_t block_local(int64_t i) const { return begin + i; }
    SDF_CPU_GPU Vec3d position(int64_t i) const { return points[begin + i]; }
    SDF_CPU_GPU int64_t output_index(int64_t i) const { return begin + i; }
};

/// Points sorted on the device (e.g. into Morton order): position i of the sorted list,
/// whose result goes back to the input position original[begin + i] (scattered), or by its
/// rank (gathered, ResultOrder; original null).
struct SortedPointListPiece {
    const Vec3d* sorted = nullptr;
    const int64_t* original = nullptr;  ///< null: results gathered by rank (ResultOrder), not scattered
    int64_t begin = 0;
    int64_t count = 0;

    SDF_CPU_GPU int64_t size() const { return count; }
    SDF_CPU_GPU int64_t block_local(int64_t i) const { return begin + i; }
    SDF_CPU_GPU Vec3d position(int64_t i) const { return sorted[begin + i]; }
    SDF_CPU_GPU int64_t output_index(int64_t i) const { return original ? original[begin + i] : begin + i; }
};

}  // namespace sdf::cuda
