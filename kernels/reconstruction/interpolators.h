/// @file interpolators.h
/// @brief All reconstruction filters, and the one dispatch point from a run-time choice to
/// the compile-time interpolator type:
///
///   visit_interpolator(kind, [&](auto interp) {
///       using I = decltype(interp);
///       return I::evaluate(view, p);
///   });
///
/// Adding an interpolator is one header plus one enum value and one case here.
#pragma once

#include "kernels/reconstruction/bcc_cubic.h"
#include "kernels/reconstruction/bcc_cubic_c0.h"
#include "kernels/reconstruction/bcc_linear.h"
#include "kernels/reconstruction/catmull_rom.h"
#include "kernels/reconstruction/tricubic_lekien_marsden.h"
#include "kernels/reconstruction/trilinear.h"

namespace sdf {

enum class InterpolatorKind : int { Trilinear, CatmullRom, TricubicLM, BccLinear, BccCubic, BccCubicC0 };

constexpr int kInterpolatorKinds = 6;

template <typename F>
SDF_CPU_GPU decltype(auto) visit_interpolator(InterpolatorKind kind, F&& f) {
    switch (kind) {
        case InterpolatorKind::Trilinear: return f(Trilinear{});
        case InterpolatorKind::CatmullRom: return f(CatmullRom{});
        case InterpolatorKind::TricubicLM: return f(TricubicLekienMarsden{});
        case InterpolatorKind::BccLinear: return f(BccLinear{});
        case InterpolatorKind::BccCubic: return f(BccCubic{});
        default: return f(BccCubicC0{});
    }
}

}  // namespace sdf
