/// @file filtered_orientation.h
/// @brief The orientation determinant of four double points with a rigorous bound on its
/// rounding, host and device: its sign where the bound decides it, "undecided" where it does
/// not. The first stage of Shewchuk's adaptive orient3d ("Adaptive Precision Floating-Point
/// Arithmetic and Fast Robust Geometric Predicates", 1997, error bound A), with no exact
/// fallback, so the same bits come out on the CPU and the GPU (no contraction into FMA on
/// either: -ffp-contract=off, --fmad=false). Callers take "undecided" as "ask someone else".
///
/// The determinant is affine in each point, so a rational point y = (x0 + x1 + x2) / 3 (a
/// triangle's centroid) enters exactly as the sum of three determinants, each with its bound:
/// no rounded coordinate of y is ever used.
#pragma once

#include <cmath>

#include "kernels/core/host_device.h"
#include "kernels/core/vec3.h"

namespace sdf {

/// A rounded value and a bound on its distance from the exact one.
struct BoundedValue {
    double value = 0, bound = 0;
};

/// The factor of the bounds' underflow terms (times a sum >= 1): 2^-1021 >= the 2^-1070 or
/// 2^-1071 each needs, and normal, so the products stay normal.
inline constexpr double kUnderflowAllowance = 0x1p-1021;

/// det[a - d, b - d, c - d] (Shewchuk's orient3d): positive when d lies on the side of the
/// plane abc away from which (b - a) x (c - a) points, i.e. behind a triangle abc.
SDF_CPU_GPU SDF_INLINE BoundedValue orientation_det(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
    const double adx = a.x - d.x, ady = a.y - d.y, adz = a.z - d.z;
    const double bdx = b.x - d.x, bdy = b.y - d.y, bdz = b.z - d.z;
    const double cdx = c.x - d.x, cdy = c.y - d.y, cdz = c.z - d.z;
    const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
    const double cdxady = cdx * ady, adxcdy = adx * cdy;
    const double adxbdy = adx * bdy, bdxady = bdx * ady;
    BoundedValue r;
    r.value = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    const double permanent = (fabs(bdxcdy) + fabs(cdxbdy)) * fabs(adz) + (fabs(cdxady) + fabs(adxcdy)) * fabs(bdz) +
                             (fabs(adxbdy) + fabs(bdxady)) * fabs(cdz);
    constexpr double eps = 1.1102230246251565404e-16;  // 2^-53
    // Shewchuk's relative bound, plus what underflow adds: a product below the normal range
    // is rounded by up to 2^-1075 absolutely (the differences are exact there), which the
    // outer products multiply by |adz|, |bdz|, |cdz|; 2^-1071 covers that and the
    // permanent's own products lost to underflow. Taken as 2^-1021, a normal factor whose
    // product with a sum >= 1 stays normal: a subnormal product costs an x86 core a microcode
    // assist, which was 40% of nearest_side()'s time. Overflow loses everything: no decision.
    r.bound = (7.0 + 56.0 * eps) * eps * permanent + kUnderflowAllowance * (fabs(adz) + fabs(bdz) + fabs(cdz) + 1.0);
    if (!(permanent < 1e300)) r.bound = INFINITY;
    return r;
}

/// The sum of three bounded values, with the sum's own rounding (two additions).
SDF_CPU_GPU SDF_INLINE BoundedValue bounded_sum(const BoundedValue& a, const BoundedValue& b, const BoundedValue& c) {
    constexpr double eps = 1.1102230246251565404e-16;
    BoundedValue r;
    r.value = (a.value + b.value) + c.value;
    r.bound = (a.bound + b.bound + c.bound + 2.0 * eps * (fabs(a.value) + fabs(b.value) + fabs(c.value))) * (1.0 + 8.0 * eps);
    return r;
}

/// +1 or -1 where the bound decides the exact value's sign, 0 where it does not (the exact
/// value may be 0).
SDF_CPU_GPU SDF_INLINE int decided_sign(const BoundedValue& v) {
    if (v.value > v.bound) return 1;
    if (v.value < -v.bound) return -1;
    return 0;
}

}  // namespace sdf
