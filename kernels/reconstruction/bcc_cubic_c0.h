/// @file bcc_cubic_c0.h
/// @brief A face-consistent variant of the BCC cubic Hermite spline: continuous (C0) across
/// tetrahedron faces, still reproducing every cubic (order 4).
///
/// On a face, the restriction of the Bernstein-Bezier cubic depends only on the face's 10
/// coefficients: 3 vertex and 6 edge coefficients, fixed by the face's own vertex data, and
/// the face-centre coefficient. bcc_cubic (eq. 4-9) chooses the latter from all 4 vertices,
/// so two tetrahedra sharing a face disagree on it. Here each face-centre coefficient is the
/// least-squares fit of the *tangential* second derivatives at the face's 3 vertices,
///   c_F = argmin sum_{v in F} || P (H_p(v) - H_f(v)) P ||_F^2,   P = I - n n^T,
/// where H_f is the full Hessian estimate from the 27-point stencils (eqs. 4-12..4-15) and
/// P H_p P depends only on the face's coefficients. The fit is intrinsic to the face, so both
/// tetrahedra compute the same c_F: the spline is continuous. For a cubic f with exact data
/// the minimum is zero at the true coefficient, so cubics are reproduced. Gradients still
/// jump across faces (C1 would need a split element such as Clough-Tocher).
///
/// The weights come from bcc_cubic_tables.h's bcc_cubic_c0_face_table() (their columns for
/// the opposite vertex are zero); the view must hold all 6 second derivatives
/// (kBccFullStride).
#pragma once

#include "kernels/reconstruction/bcc_cubic.h"

namespace sdf {

struct BccCubicC0 {
    SDF_CPU_GPU static constexpr const char* name() { return "bcc_cubic_c0"; }
    SDF_CPU_GPU static constexpr int radius() { return 1; }
    SDF_CPU_GPU static constexpr int order() { return 4; }
    SDF_CPU_GPU static constexpr bool interpolating() { return true; }
    SDF_CPU_GPU static constexpr LatticeType lattice_type() { return LatticeType::BCC; }
    SDF_CPU_GPU static constexpr bool uses_first() { return true; }
    SDF_CPU_GPU static constexpr int higher_stride() { return kBccFullStride; }
    SDF_CPU_GPU static constexpr PointData point_data() { return PointData::BccCubicC0Jet; }
    SDF_CPU_GPU static constexpr int min_resolution() { return 4; }

    template <typename T>
    SDF_CPU_GPU static DomainBox<T> domain(const LatticeFieldView<T>& v) { return bcc_domain(v); }
    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate_in(const LatticeFieldView<T>& v, const BccTetrahedron& tet,
                                                          const Vec3<T>& u) {
        SDF_DCHECK(v.higher_stride >= kBccFullStride);
        return bcc_cubic_evaluate_in(v, tet, u);
    }
    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate(const LatticeFieldView<T>& v, const Vec3<T>& p) {
        SDF_DCHECK(v.higher_stride >= kBccFullStride);
        return bcc_cubic_evaluate(v, p);
    }
};

}  // namespace sdf
