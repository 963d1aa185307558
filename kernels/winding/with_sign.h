/// @file with_sign.h
/// @brief Gives a sample the sign decided elsewhere (e.g. by the winding number): distance
/// and gradient keep their exact magnitude and direction, only the side changes.
#pragma once

#include "kernels/distance/signed_distance.h"

namespace sdf {

/// `s` with distance -|d| when `inside`, +|d| otherwise; the gradient (the unit vector
/// from the closest point, times the sign) flips with it. A sample at distance 0 keeps its
/// pseudonormal gradient.
template <typename T>
SDF_CPU_GPU SDF_INLINE SignedDistanceSample<T> with_sign(SignedDistanceSample<T> s, bool inside) {
    if (s.distance != T(0) && inside != (s.distance < T(0))) {
        s.distance = -s.distance;
        s.gradient = -s.gradient;
    }
    return s;
}

}  // namespace sdf
