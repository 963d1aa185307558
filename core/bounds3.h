/// @file bounds3.h
/// @brief Axis-aligned bounds of points: the one box type of the host code (meshes, BVH build,
/// lattice fitting, cameras). At core/'s root, below every core/ subfolder, so that the BVH
/// build (core/bvh) needs nothing of core/mesh.
#pragma once

#include "kernels/core/vec3.h"

namespace sdf {

struct Bounds3 {
    Vec3d min{1e300, 1e300, 1e300};
    Vec3d max{-1e300, -1e300, -1e300};
    void extend(const Vec3d& p) { min = component_min(min, p); max = component_max(max, p); }
    Vec3d extent() const { return max - min; }
    Vec3d center() const { return (min + max) * 0.5; }
    double diagonal() const { return length(max - min); }
    bool empty() const { return min.x > max.x; }
};

}  // namespace sdf
