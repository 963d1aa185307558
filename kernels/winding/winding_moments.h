/// @file winding_moments.h
/// @brief What the fast winding number stores for each child of a BVH node: the moments of
/// its triangles about their area-weighted centroid (Barill, Dickson, Schmidt, Levin &
/// Jacobson, "Fast Winding Numbers for Soups and Clouds", SIGGRAPH 2018, section 3.2).
///
/// One WindingNode per BvhNode, same index, both children side by side like the boxes, so
/// the traversal reads the node and its moments with the same index.
#pragma once

#include "kernels/core/vec3.h"

namespace sdf {

template <typename T>
struct WindingMoments {
    Vec3<T> center{};      ///< p~ = sum a_i c_i / sum a_i (triangle centroids c_i, areas a_i)
    T radius{};            ///< r = max |v - p~| over the child's vertices: the ball holds every triangle
    T area{};              ///< A = sum a_i (unsigned), for the error bound
    Vec3<T> normal_sum{};  ///< N = sum a_i n_i (order 1: the dipole)
    T second[9]{};         ///< M = sum a_i (c_i - p~) n_i^T, row-major (order 2)
};

template <typename T>
struct WindingNode {
    WindingMoments<T> child[2];
};

/// The moments rounded to float (to nearest), for the far field's float evaluation
/// (far_field_float(), fast_winding_number.h); host and device round alike.
SDF_CPU_GPU inline WindingNode<float> rounded_to_float(const WindingNode<double>& n) {
    WindingNode<float> f;
    for (int c = 0; c < 2; ++c) {
        const WindingMoments<double>& m = n.child[c];
        WindingMoments<float>& r = f.child[c];
        r.center = Vec3<float>(float(m.center.x), float(m.center.y), float(m.center.z));
        r.radius = float(m.radius);
        r.area = float(m.area);
        r.normal_sum = Vec3<float>(float(m.normal_sum.x), float(m.normal_sum.y), float(m.normal_sum.z));
        for (int k = 0; k < 9; ++k) r.second[k] = float(m.second[k]);
    }
    return f;
}

}  // namespace sdf
