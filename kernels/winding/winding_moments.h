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

}  // namespace sdf
