/// @file trilinear.h
/// @brief Trilinear interpolation on the CC lattice: the tensor product of linear
/// interpolation along each axis over the cell's 8 corners. Order 2, C0; the gradient is the
/// exact derivative of the trilinear piece (discontinuous across cell faces).
#pragma once

#include "kernels/reconstruction/cc_cell.h"

namespace sdf {

struct Trilinear {
    SDF_CPU_GPU static constexpr const char* name() { return "trilinear"; }
    SDF_CPU_GPU static constexpr int radius() { return 1; }
    SDF_CPU_GPU static constexpr int order() { return 2; }
    SDF_CPU_GPU static constexpr bool interpolating() { return true; }
    SDF_CPU_GPU static constexpr LatticeType lattice_type() { return LatticeType::CC; }
    SDF_CPU_GPU static constexpr bool uses_first() { return false; }
    SDF_CPU_GPU static constexpr int higher_stride() { return 0; }
    SDF_CPU_GPU static constexpr PointData point_data() { return PointData::Values; }
    SDF_CPU_GPU static constexpr int min_resolution() { return 2; }

    template <typename T>
    SDF_CPU_GPU static DomainBox<T> domain(const LatticeFieldView<T>& v) { return cc_domain(v); }

    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate(const LatticeFieldView<T>& v, const Vec3<T>& p) {
        const CcCell<T> cell = cc_cell_at(v, p);
        // Gather the 8 corners, x fastest
        T f[8];
        for (int c = 0; c < 8; ++c)
            f[c] = v.values[cc_index(v.lattice, cell.corner.x + (c & 1), cell.corner.y + ((c >> 1) & 1),
                                     cell.corner.z + (c >> 2))];
        const T x = cell.t.x, y = cell.t.y, z = cell.t.z;
        // Reduce along x, then y, then z, keeping the derivatives
        T fx[4], dx[4];
        for (int i = 0; i < 4; ++i) {
            fx[i] = f[2 * i] + x * (f[2 * i + 1] - f[2 * i]);
            dx[i] = f[2 * i + 1] - f[2 * i];
        }
        const T fy0 = fx[0] + y * (fx[1] - fx[0]), fy1 = fx[2] + y * (fx[3] - fx[2]);
        const T dxy0 = dx[0] + y * (dx[1] - dx[0]), dxy1 = dx[2] + y * (dx[3] - dx[2]);
        const T dy0 = fx[1] - fx[0], dy1 = fx[3] - fx[2];
        ReconstructedSample<T> s;
        s.value = fy0 + z * (fy1 - fy0);
        s.gradient = Vec3<T>(dxy0 + z * (dxy1 - dxy0), dy0 + z * (dy1 - dy0), fy1 - fy0) * v.inv_unit;
        s.inside = cell.inside;
        return s;
    }
};

}  // namespace sdf
