/// @file bcc_linear.h
/// @brief Piecewise linear interpolation on the BCC lattice: barycentric interpolation of
/// the 4 vertex values in the Delaunay tetrahedron holding the point (thesis eq. 4-1). C0,
/// order 2; the gradient is constant per tetrahedron.
#pragma once

#include "kernels/reconstruction/bcc_tetrahedron.h"

namespace sdf {

struct BccLinear {
    SDF_CPU_GPU static constexpr const char* name() { return "bcc_linear"; }
    SDF_CPU_GPU static constexpr int radius() { return 1; }
    SDF_CPU_GPU static constexpr int order() { return 2; }
    SDF_CPU_GPU static constexpr bool interpolating() { return true; }
    SDF_CPU_GPU static constexpr LatticeType lattice_type() { return LatticeType::BCC; }
    SDF_CPU_GPU static constexpr bool uses_first() { return false; }
    SDF_CPU_GPU static constexpr int higher_stride() { return 0; }
    SDF_CPU_GPU static constexpr PointData point_data() { return PointData::Values; }
    SDF_CPU_GPU static constexpr int min_resolution() { return 3; }

    template <typename T>
    SDF_CPU_GPU static DomainBox<T> domain(const LatticeFieldView<T>& v) { return bcc_domain(v); }

    /// The linear piece of tetrahedron `tet` at lattice coordinates u (any u: the piece is
    /// extended beyond its tetrahedron, which the continuity tests use).
    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate_in(const LatticeFieldView<T>& v, const BccTetrahedron& tet,
                                                          const Vec3<T>& u) {
        T lambda[4];
        bcc_reference_barycentrics(tet.to_reference(u), lambda);
        ReconstructedSample<T> s;
        Vec3<T> g_ref(T(0));
        for (int k = 0; k < 4; ++k) {
            const T f = v.values[bcc_index(v.lattice, tet.vertex(k))];
            s.value += lambda[k] * f;
            g_ref += bcc_reference_barycentric_gradient<T>(k) * f;
        }
        s.gradient = tet.vector_from_reference(g_ref) * v.inv_unit;
        return s;
    }

    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate(const LatticeFieldView<T>& v, const Vec3<T>& p) {
        Vec3<T> u = v.to_lattice(p);
        const bool inside = clamp_to_bcc_domain(v.lattice, u);
        ReconstructedSample<T> s = evaluate_in(v, bcc_tetrahedron_at(v.lattice, u), u);
        s.inside = inside;
        return s;
    }
};

}  // namespace sdf
