/// @file lattice.h
/// @brief Cartesian (CC) and body-centred cubic (BCC) lattices: geometry and indexing.
///
/// A lattice has an origin, an isotropic spacing h and a resolution. The BCC lattice uses
/// the thesis's notation Rx x Ry x 2Rz (section 3.3, Figure 3-3 B): a "primary" CC grid of
/// Rx x Ry x Rz points plus a "secondary" grid of (Rx-1) x (Ry-1) x (Rz-1) points shifted by
/// h/2 along every axis, i.e. one point at the centre of every primary cube.
///
/// Internally every point has integer coordinates in units of h/2 (DESIGN.md): CC points are
/// all-even; BCC points are all-even (primary) or all-odd (secondary). Every position is
/// computed as origin + (h/2) * integer_coords, so the two BCC sampling strategies and the
/// CPU and GPU samplers produce bit-identical positions.
///
/// Storage order: x fastest, then y, then z. A BCC field stores the primary grid first and
/// the secondary grid after it.
#pragma once

#include <cstdint>

#include "kernels/core/vec3.h"
#include "kernels/lattice/lattice_kinds.h"

namespace sdf {

struct Lattice {
    LatticeType type{LatticeType::CC};
    Vec3d origin{};
    double spacing{1.0};  ///< h: distance between neighbouring primary points along an axis
    Int3 resolution{};    ///< CC: points per axis; BCC: the primary grid (Rx, Ry, Rz)

    SDF_CPU_GPU double half_spacing() const { return 0.5 * spacing; }

    SDF_CPU_GPU int64_t primary_count() const {
        return int64_t(resolution.x) * resolution.y * resolution.z;
    }
    SDF_CPU_GPU Int3 secondary_resolution() const {
        return {resolution.x - 1, resolution.y - 1, resolution.z - 1};
    }
    SDF_CPU_GPU int64_t secondary_count() const {
        if (type != LatticeType::BCC) return 0;
        Int3 r = secondary_resolution();
        return (r.x > 0 && r.y > 0 && r.z > 0) ? int64_t(r.x) * r.y * r.z : 0;
    }
    SDF_CPU_GPU int64_t num_points() const { return primary_count() + secondary_count(); }

    /// World position of integer coordinates in units of h/2.
    SDF_CPU_GPU Vec3d position_of_coords(const Int3& c) const {
        const double hh = half_spacing();
        return {origin.x + hh * double(c.x), origin.y + hh * double(c.y), origin.z + hh * double(c.z)};
    }

    /// Integer coordinates (units of h/2) of the point stored at `index`.
    SDF_CPU_GPU Int3 coords_of(int64_t index) const {
        const bool secondary = index >= primary_count();
        const Int3 r = secondary ? secondary_resolution() : resolution;
        const int64_t local = secondary ? index - primary_count() : index;
        const int i = int(local % r.x);
        const int j = int((local / r.x) % r.y);
        const int k = int(local / (int64_t(r.x) * r.y));
        const int odd = secondary ? 1 : 0;
        return {2 * i + odd, 2 * j + odd, 2 * k + odd};
    }

    SDF_CPU_GPU Vec3d position(int64_t index) const { return position_of_coords(coords_of(index)); }

    /// Storage index of the point with integer coordinates c, or -1 if c is not a point of
    /// this lattice (mixed parity, odd on CC, or outside the resolution).
    SDF_CPU_GPU int64_t index_of_coords(const Int3& c) const {
        const int px = c.x & 1, py = c.y & 1, pz = c.z & 1;
        if (px != py || py != pz) return -1;
        if (px == 1 && type != LatticeType::BCC) return -1;
        const Int3 r = px ? secondary_resolution() : resolution;
        const int i = (c.x - px) / 2, j = (c.y - py) / 2, k = (c.z - pz) / 2;
        if (c.x < 0 || c.y < 0 || c.z < 0 || i >= r.x || j >= r.y || k >= r.z) return -1;
        const int64_t local = i + int64_t(r.x) * (j + int64_t(r.y) * k);
        return px ? primary_count() + local : local;
    }

    /// Axis-aligned box spanned by the primary grid.
    SDF_CPU_GPU Vec3d domain_min() const { return origin; }
    SDF_CPU_GPU Vec3d domain_max() const {
        return {origin.x + spacing * (resolution.x - 1), origin.y + spacing * (resolution.y - 1),
                origin.z + spacing * (resolution.z - 1)};
    }
};

/// Offsets (units of h/2) of the 26 BCC neighbours that, with the centre, make the 27-point
/// neighbourhood of thesis section 4.1.3 / Figure 4-2: 8 at (+-1,+-1,+-1), 6 at (+-2,0,0)...,
/// and 12 at (+-2,+-2,0).... Index 0 is the centre.
SDF_CPU_GPU inline Int3 bcc_neighbour_offset(int n) {
    // Centre, 8 body diagonals, 6 axis neighbours, 12 face diagonals.
    constexpr int table[27][3] = {
        {0, 0, 0},
        {-1, -1, -1}, {1, -1, -1}, {-1, 1, -1}, {1, 1, -1},
        {-1, -1, 1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, 1},
        {-2, 0, 0}, {2, 0, 0}, {0, -2, 0}, {0, 2, 0}, {0, 0, -2}, {0, 0, 2},
        {-2, -2, 0}, {2, -2, 0}, {-2, 2, 0}, {2, 2, 0},
        {-2, 0, -2}, {2, 0, -2}, {-2, 0, 2}, {2, 0, 2},
        {0, -2, -2}, {0, 2, -2}, {0, -2, 2}, {0, 2, 2},
    };
    return {table[n][0], table[n][1], table[n][2]};
}

/// Offsets (units of h/2) of the 27-point CC neighbourhood (3x3x3 block), centre first.
SDF_CPU_GPU inline Int3 cc_neighbour_offset(int n) {
    if (n == 0) return {0, 0, 0};
    const int m = n <= 13 ? n - 1 : n;  // skip the centre in the 3x3x3 enumeration
    return {2 * (m % 3 - 1), 2 * ((m / 3) % 3 - 1), 2 * (m / 9 - 1)};
}

}  // namespace sdf
