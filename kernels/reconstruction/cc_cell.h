/// @file cc_cell.h
/// @brief Locates the CC cell holding a point: the cell's lower corner and the local
/// coordinates t in [0,1]^3, after clamping the point to the grid's box (interpolator.h).
#pragma once

#include <cmath>

#include "kernels/reconstruction/interpolator.h"
#include "kernels/reconstruction/lattice_field_view.h"

namespace sdf {

template <typename T>
struct CcCell {
    Int3 corner{};  ///< lower corner (i, j, k), 0 <= i <= n-2
    Vec3<T> t{};    ///< position inside the cell, [0,1]^3
    bool inside{true};
};

/// The box of the CC grid in world units.
template <typename T>
SDF_CPU_GPU DomainBox<T> cc_domain(const LatticeFieldView<T>& v) {
    const Int3 r = v.lattice.resolution;
    return {v.origin, v.to_world(Vec3<T>(T(r.x - 1), T(r.y - 1), T(r.z - 1)))};
}

template <typename T>
SDF_CPU_GPU CcCell<T> cc_cell_at(const LatticeFieldView<T>& v, const Vec3<T>& p) {
    const Int3 r = v.lattice.resolution;
    Vec3<T> u = v.to_lattice(p);
    CcCell<T> cell;
    cell.inside = clamp_to_box(u, Vec3<T>(T(0)), Vec3<T>(T(r.x - 1), T(r.y - 1), T(r.z - 1)));
    for (int a = 0; a < 3; ++a) {
        int i = int(std::floor(u[a]));
        i = i > r[a] - 2 ? r[a] - 2 : i;  // the last grid plane belongs to the last cell
        i = i < 0 ? 0 : i;                // a grid with one point on this axis
        cell.corner[a] = i;
        cell.t[a] = u[a] - T(i);
    }
    return cell;
}

}  // namespace sdf
