/// @file interpolator.h
/// @brief The one interface every reconstruction filter provides (CC and BCC alike), in the
/// manner of OpenVDB's tools/Interpolation.h, plus the sample type they return.
///
/// An interpolator is an empty struct with only static members, so the ray caster, the
/// metrics and the tests take any of them as a template parameter:
///
///   static const char* name();          // "trilinear", "bcc_cubic", ... (config names)
///   static int radius();                // support radius in units of h: the data a point's
///                                       // value depends on, given the per-point arrays of
///                                       // its LatticeFieldView (fd widens the footprint in
///                                       // the raw samples: see docs/reconstruction.md)
///   static int order();                 // approximation order with exact derivative data:
///                                       // error O(h^order); it reproduces every polynomial
///                                       // of degree order-1 (Strang-Fix, thesis 4.1.2)
///   static bool interpolating();        // reproduces the lattice values
///   static LatticeType lattice_type();  // CC or BCC
///   static bool uses_first();           // reads LatticeFieldView::first
///   static int higher_stride();         // LatticeFieldView::higher entries it reads per point
///   static PointData point_data();      // which per-point arrays core/reconstruction builds
///   static int min_resolution();        // primary lattice points per axis it needs
///   template <typename T> static DomainBox<T> domain(const LatticeFieldView<T>&);
///   template <typename T> static ReconstructedSample<T> evaluate(const LatticeFieldView<T>&,
///                                                                const Vec3<T>& p);
///
/// evaluate() takes a world-space point and returns the value and the world-space gradient
/// (the exact derivative of the piecewise polynomial). Points outside domain() are clamped
/// to it first (component-wise, so the result is continuous and well defined) and the
/// sample is flagged `inside = false`; a ray caster marches inside domain().
#pragma once

#include "kernels/core/vec3.h"

namespace sdf {

/// The per-point arrays of a LatticeFieldView that an interpolator reads beyond the values;
/// core/reconstruction/hermite_data builds them with one case per enumerator (a new layout
/// without its case is a -Wswitch warning, an error in developers' builds).
enum class PointData {
    Values,         ///< the lattice values alone
    CcTricubicJet,  ///< CC: gradient and the cross derivatives fxy, fxz, fyz, fxyz (Lekien-Marsden)
    BccCubicJet,    ///< BCC: gradient and the mixed second derivatives (thesis eq. 4-3..4-9)
    BccCubicC0Jet,  ///< BCC: gradient and all second derivatives, face-local centre data
    SplineInterpolation,       ///< spline coefficients of the interpolation prefilter (stride 1)
    SplineQuasiInterpolation,  ///< spline coefficients of the quasi-interpolation prefilter (stride 1)
};

template <typename T>
struct ReconstructedSample {
    T value{};
    Vec3<T> gradient{};  ///< world units: d value / d position
    bool inside{true};   ///< false when p lay outside domain() and was clamped into it
};

/// Axis-aligned box in world units.
template <typename T>
struct DomainBox {
    Vec3<T> lo{}, hi{};
};

/// Clamps lattice coordinates u into [lo, hi] on every axis; returns whether u was inside.
template <typename T>
SDF_CPU_GPU bool clamp_to_box(Vec3<T>& u, const Vec3<T>& lo, const Vec3<T>& hi) {
    bool inside = true;
    for (int i = 0; i < 3; ++i) {
        if (u[i] < lo[i]) { u[i] = lo[i]; inside = false; }
        if (u[i] > hi[i]) { u[i] = hi[i]; inside = false; }
        if (!(u[i] == u[i])) { u[i] = lo[i]; inside = false; }  // NaN
    }
    return inside;
}

}  // namespace sdf
