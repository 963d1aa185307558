/// @file triangle_bvh.h
/// @brief A BVH over a mesh's triangles, built on the CPU with binned SAH (Wald,
/// "On fast Construction of SAH-based Bounding Volume Hierarchies", IEEE RT 2007) into the
/// flat layout of kernels/bvh/bvh_node.h, with the search constants of every triangle
/// stored in BVH order for the float and the double query.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/bounds3.h"
#include "core/default_init_vector.h"
#include "kernels/bvh/bvh_view.h"
#include "kernels/core/vec3.h"
#include "kernels/distance/packed_triangle.h"
#include "kernels/distance/search_certificate.h"

namespace sdf {

struct BvhBuildOptions {
    int max_leaf_size = 4;        ///< leaves hold at most this many triangles (except unsplittable ranges)
    int bins = 32;                ///< SAH bins per axis
    double node_cost = 1.0;       ///< SAH cost of visiting a node, relative to one triangle test
    int median_split_depth = 32;  ///< below this depth, split at the object median (bounds the depth)
    /// Threads of the build (0: all hardware threads). The tree does not depend on it.
    int threads = 0;
};

struct BvhBuildStats {
    int nodes = 0, leaves = 0, depth = 0, largest_leaf = 0;
    double sah_cost = 0;  ///< expected cost of a query through the root, in triangle tests
    double seconds = 0;
    nlohmann::json to_json() const;
};

class TriangleBvh {
public:
    // Filled by the build on every thread: allocated unwritten, in huge pages where Linux
    // offers them (default_init_vector.h); zero-filled, 30 MB for a mesh of 100k triangles
    // cost more in page faults than the build's own work (dragon, 2 threads: 0.16 -> 0.06 s).
    std::vector<BvhNode> nodes;
    DefaultInitVector<int32_t> triangle_index;  ///< BVH slot -> prepared-mesh triangle
    DefaultInitVector<PackedTriangle<float>> packed_float;    ///< search constants in BVH order
    DefaultInitVector<PackedTriangle<double>> packed_double;
    BvhBuildStats stats;
    /// The certified float search's bound of these triangles (search_bound.h), computed by
    /// the build so that a query does not pass over the mesh; empty for a tree made otherwise.
    std::optional<FloatSearchBound> float_bound;

    template <typename T>
    BvhView<T> view() const;
};

/// What the build reads of a mesh: its triangles and their search constants (a PreparedMesh's
/// arrays, core/mesh/prepared_mesh.h). A view of plain arrays, so that core/bvh sits below
/// core/mesh, which builds a BVH to find self-intersections (scripts/check-layers).
struct BvhBuildInput {
    const std::vector<Vec3d>& vertices;
    const std::vector<Int3>& triangles;
    const DefaultInitVector<PackedTriangle<float>>& packed_float;    ///< one per triangle, in triangle order
    const DefaultInitVector<PackedTriangle<double>>& packed_double;
    const std::string& name;  ///< for messages
    /// The float search's bound of these arrays where the caller has it already (a prepared
    /// mesh makes it once: PreparedMesh::search_bound()); null: the build computes it.
    const FloatSearchBound* search_bound = nullptr;
};

/// Builds the BVH of the triangles (throws std::invalid_argument for an empty mesh).
TriangleBvh build_triangle_bvh(const BvhBuildInput& input, const BvhBuildOptions& options = {});

/// The BVH of a PreparedMesh (or anything with its vertices(), triangles(), buffers<T>(), name()
/// and search_bound()); a template only so that this layer needs no include of core/mesh.
template <class Mesh>
TriangleBvh build_triangle_bvh(const Mesh& mesh, const BvhBuildOptions& options = {}) {
    return build_triangle_bvh(BvhBuildInput{mesh.vertices(), mesh.triangles(), mesh.template buffers<float>().packed,
                                            mesh.template buffers<double>().packed, mesh.name(), &mesh.search_bound()},
                              options);
}

/// Expected triangle tests of a point query through the root of `nodes` under the SAH's
/// model (BvhBuildStats::sah_cost), for any builder's flat tree.
double bvh_sah_cost(const std::vector<BvhNode>& nodes, double node_cost = 1.0);

/// The same box, rounded outward from double to float so that it still contains the input.
float round_down_to_float(double x);
float round_up_to_float(double x);

}  // namespace sdf
