/// @file bcc_box_linear.h
/// @brief The four-direction linear box spline of the BCC lattice (Entezari, Van De Ville,
/// Moeller, "Practical box splines for reconstruction on the body centered cubic lattice",
/// IEEE TVCG 14(2), 2008): s(u) = sum_k f_k phi4(u - k).
///
/// phi4 is the box spline of the four body diagonals (+-1,+-1,+-1) (one of each antipodal
/// pair), scaled to a partition of unity. In lattice units (h/2) its explicit form is
///   phi4(x) = max(0, 1 - (a1 + a2) / 2),  a1 >= a2 the two largest of |x|, |y|, |z|
/// (scripts/derive/bcc_box_splines.py derives it from the definition; the tests check it
/// against the convolution integral). Support: the rhombic dodecahedron |x_i| + |x_j| <= 2
/// whose 14 vertices are the nearest lattice neighbours; phi4(0) = 1 and it vanishes at every
/// other lattice point, so the spline interpolates with no prefilter. It is linear on every
/// Delaunay tetrahedron: mathematically the same function as bcc_linear (barycentric
/// interpolation), here evaluated as a box spline sum over the 16 corners of the primary and
/// secondary cubes around u. C0; reproduces degree 1; order 2.
#pragma once

#include <cmath>

#include "kernels/reconstruction/bcc_tetrahedron.h"
#include "kernels/reconstruction/spline_coefficients.h"

namespace sdf {

/// phi4 and its gradient at x (lattice units).
template <typename T>
SDF_CPU_GPU void bcc_box_linear_kernel(const Vec3<T>& x, T& value, Vec3<T>& gradient) {
    const T a[3] = {std::abs(x.x), std::abs(x.y), std::abs(x.z)};
    // The axis of the smallest |x_i| drops out
    const int smallest = (a[0] <= a[1] && a[0] <= a[2]) ? 0 : (a[1] <= a[2] ? 1 : 2);
    const int i = smallest == 0 ? 1 : 0, j = smallest == 2 ? 1 : 2;
    value = T(1) - (a[i] + a[j]) / T(2);
    gradient = Vec3<T>(T(0));
    if (value <= T(0)) {
        value = T(0);
        return;
    }
    gradient[i] = x[i] < T(0) ? T(0.5) : T(-0.5);
    gradient[j] = x[j] < T(0) ? T(0.5) : T(-0.5);
}

template <typename T>
SDF_CPU_GPU T bcc_box_linear_kernel(const Vec3<T>& x) {
    T value;
    Vec3<T> gradient;
    bcc_box_linear_kernel(x, value, gradient);
    return value;
}

struct BccBoxLinear {
    SDF_CPU_GPU static constexpr const char* name() { return "bcc_box_linear"; }
    SDF_CPU_GPU static constexpr int radius() { return 1; }
    SDF_CPU_GPU static constexpr int order() { return 2; }
    SDF_CPU_GPU static constexpr bool interpolating() { return true; }
    SDF_CPU_GPU static constexpr LatticeType lattice_type() { return LatticeType::BCC; }
    SDF_CPU_GPU static constexpr bool uses_first() { return false; }
    SDF_CPU_GPU static constexpr int higher_stride() { return 0; }
    SDF_CPU_GPU static constexpr SplinePrefilter prefilter() { return SplinePrefilter::None; }
    SDF_CPU_GPU static constexpr PointData point_data() { return spline_point_data(prefilter()); }
    SDF_CPU_GPU static constexpr int min_resolution() { return 3; }

    /// The secondary points' box, as bcc_linear: every lattice point whose phi4 reaches a
    /// point of it exists.
    template <typename T>
    SDF_CPU_GPU static DomainBox<T> domain(const LatticeFieldView<T>& v) { return bcc_domain(v); }

    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate(const LatticeFieldView<T>& v, const Vec3<T>& p) {
        Vec3<T> u = v.to_lattice(p);
        const bool inside = clamp_to_bcc_domain(v.lattice, u);
        ReconstructedSample<T> s;
        s.inside = inside;
        // phi4(u - k) > 0 only for |u_i - k_i| < 2: the corners of the primary (even) and the
        // secondary (odd) cube holding u. Lower corners clamped so that all 16 exist; inside
        // the domain the clamped cube still holds u.
        for (int parity = 0; parity < 2; ++parity) {
            Int3 lower;
            for (int i = 0; i < 3; ++i) {
                const int top = 2 * v.lattice.resolution[i] - 2 - parity;  // last coordinate of this parity
                const int c = 2 * int(std::floor((u[i] - T(parity)) / T(2))) + parity;
                lower[i] = c > top - 2 ? top - 2 : (c < parity ? parity : c);
            }
            for (int corner = 0; corner < 8; ++corner) {
                const Int3 k{lower.x + 2 * (corner & 1), lower.y + (corner & 2), lower.z + ((corner >> 1) & 2)};
                T w;
                Vec3<T> dw;
                bcc_box_linear_kernel(u - Vec3<T>(T(k.x), T(k.y), T(k.z)), w, dw);
                if (w == T(0)) continue;
                const T f = v.values[bcc_index(v.lattice, k)];
                s.value += w * f;
                s.gradient += dw * f;
            }
        }
        s.gradient *= v.inv_unit;
        return s;
    }
};

}  // namespace sdf
