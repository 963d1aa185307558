/// @file directed_rounding.h
/// @brief A double rounded to float toward -infinity or +infinity, for host and device: the
/// float boxes of every BVH (the host SAH build and the GPU build) must hold their double
/// triangles, so their bounds are rounded outward exactly, not to nearest.
#pragma once

#include <cmath>
#include <limits>

#include "kernels/core/host_device.h"

namespace sdf {

/// The largest float <= x.
SDF_CPU_GPU SDF_INLINE float float_below(double x) {
#if SDF_IS_GPU_CODE
    return __double2float_rd(x);
#else
    float f = float(x);
    if (double(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return f;
#endif
}

/// The smallest float >= x.
SDF_CPU_GPU SDF_INLINE float float_above(double x) {
#if SDF_IS_GPU_CODE
    return __double2float_ru(x);
#else
    float f = float(x);
    if (double(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return f;
#endif
}

}  // namespace sdf
