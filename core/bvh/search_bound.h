/// @file search_bound.h
/// @brief The constants of the certified float search's error bound
/// (kernels/distance/search_certificate.h) for a set of triangles, from the arrays a BVH is
/// built from: computed once with the BVH and kept in it, so that a query of one point does
/// not pay a pass over the whole mesh.
#pragma once

#include <vector>

#include "core/default_init_vector.h"
#include "kernels/core/vec3.h"
#include "kernels/distance/packed_triangle.h"
#include "kernels/distance/search_certificate.h"

namespace sdf {

/// The smallest sin^2 of an angle of the non-sliver triangles (per precision), the longest
/// |E0| + |E1| and the largest |coordinate|, folded into the bound's constants; the
/// minima and maxima over chunks on `threads` threads (0 = all) are the one pass's.
FloatSearchBound float_search_bound(const std::vector<Vec3d>& vertices, const std::vector<Int3>& triangles,
                                    const DefaultInitVector<PackedTriangle<double>>& packed_double,
                                    const DefaultInitVector<PackedTriangle<float>>& packed_float, int threads = 1);

}  // namespace sdf
