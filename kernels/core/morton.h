/// @file morton.h
/// @brief Morton (Z-order) keys of points in a box, for host and device: sorting arbitrary
/// query points by these keys makes neighbours in the list neighbours in space, so packets
/// of consecutive points share BVH traversals as lattice bricks do (issue 14).
///   Morton, "A computer oriented geodetic data base...", IBM 1966; the bit spreading is the
///   usual magic-number interleave (e.g. Karras, "Maximizing Parallelism in the Construction
///   of BVHs, Octrees, and k-d Trees", HPG 2012).
#pragma once

#include <cstdint>

#include "kernels/core/host_device.h"

namespace sdf {

/// Spreads the low 21 bits of v so that bit i lands on bit 3i.
SDF_CPU_GPU SDF_INLINE uint64_t morton_spread_21(uint64_t v) {
    v &= 0x1fffffu;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

/// The 63-bit Morton key of cell (ix, iy, iz), each in [0, 2^21).
SDF_CPU_GPU SDF_INLINE uint64_t morton_key_63(uint32_t ix, uint32_t iy, uint32_t iz) {
    return morton_spread_21(ix) | morton_spread_21(iy) << 1 | morton_spread_21(iz) << 2;
}

/// The key of point (x, y, z) in the box [lo, lo + 1/inv_extent): each coordinate quantised
/// to 2^21 cells and clamped, so points outside the box (and NaN) still get a key. Only the order matters: it never changes a result, only which points share a packet.
template <typename T>
SDF_CPU_GPU SDF_INLINE uint64_t morton_key_of_point(T x, T y, T z, T lo_x, T lo_y, T lo_z, T inv_extent) {
    constexpr T kCells = T(2097151);  // 2^21 - 1
    auto cell = [&](T v, T lo) {
        T c = (v - lo) * inv_extent * kCells;
        c = c > T(0) ? (c < kCells ? c : kCells) : T(0);  // NaN -> 0
        return uint32_t(c);
    };
    return morton_key_63(cell(x, lo_x), cell(y, lo_y), cell(z, lo_z));
}

}  // namespace sdf
