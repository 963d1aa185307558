/// @file prepared_mesh.h
/// @brief A mesh made ready for exact signed distance: welded, cleaned, checked, with the
/// angle-weighted pseudonormals of faces, edges and vertices (Baerentzen & Aanaes 2005).
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "core/default_init_vector.h"
#include "core/mesh/triangle_mesh.h"
#include "kernels/distance/mesh_view.h"
#include "kernels/distance/search_certificate.h"

namespace sdf {

class TriangleBvh;  // core/bvh/triangle_bvh.h: include it to use bvh()'s tree

struct MeshPreparationOptions {
    /// Vertices closer than this (absolute, mesh units) are merged; 0 merges only
    /// bit-identical positions.
    double weld_tolerance = 0.0;
    /// Flip every triangle of a closed, consistently oriented mesh whose signed volume is
    /// negative, so that normals point outward.
    bool orient_outward = true;
    /// Look for intersecting triangle pairs (self-intersections, overlapping shells) with a
    /// BVH; costs about a BVH build (self_intersections.h).
    bool detect_intersections = true;
    /// Threads of the preparation's passes, the BVH build and the self-intersection test
    /// included (0 = all hardware threads); every result is the same bytes at any count.
    int threads = 0;
    /// Keep the input's vertices and triangles (input_vertices(), input_triangles()): the
    /// numbering of query results, for callers that have no other copy (the Python module's
    /// meshes read from files).
    bool keep_input = false;
    /// Keep what preparation derives from the faces alone (the welds, the dropped triangles,
    /// the edge adjacency, about 60 bytes a triangle), so that refit_prepared_mesh() can move
    /// the vertices without deriving it again (the Python module's SDF.refit).
    bool keep_topology = false;
};

/// A triangle's height over its longest edge (2 area / longest edge) below this fraction of the
/// mesh's largest extent E makes it a sliver within the search's rounding
/// (MeshReport::slivers_within_rounding). The double search's squared distances are exact to
/// about 2^-47 E^2 (away from the coordinates' own rounding), a distance to about 2^-47 E^2 / d
/// at d from the surface: at 2^-15 E (half a spacing of a sparse band's 16384 points per axis)
/// that is 2^-32 E. A rule measured, not proven: the fanned tetrahedron
/// (tests/cpu_reference/bvh/bvh_test_meshes.h) kept every side with slivers down to 2^-30 E,
/// also 10^4 from the origin, and lost one with slivers of 2^-45 E.
inline constexpr double kRoundingSliverHeight = 0x1p-32;

/// What preparation found; printed in summaries and stored in field headers.
struct MeshReport {
    int input_vertices = 0;
    int input_triangles = 0;
    int welded_vertices = 0;        ///< vertices merged into others
    int unreferenced_vertices = 0;  ///< dropped because no triangle uses them
    int degenerate_triangles = 0;   ///< dropped: repeated vertex or exactly zero area
    int boundary_edges = 0;         ///< used by one triangle
    int nonmanifold_edges = 0;      ///< used by more than two triangles
    int inconsistent_edges = 0;     ///< interior edges traversed in the same direction twice
    int components = 0;             ///< edge-connected pieces
    double signed_volume = 0.0;
    bool flipped = false;           ///< orientation was reversed to point outward
    bool intersections_checked = false;  ///< the two counts below were computed
    int self_intersecting_pairs = 0;     ///< intersecting triangle pairs within one shell
    int shell_intersecting_pairs = 0;    ///< intersecting triangle pairs from two shells
    int overlapping_shells = 0;          ///< pairs of shells that intersect
    /// Triangles thinner than kRoundingSliverHeight of the mesh's extent: two of their edges lie
    /// within the nearest-triangle search's rounding of each other for points near them, so
    /// the nearest feature, and with it the pseudonormal, is not decided there.
    int slivers_within_rounding = 0;
    PolygonStats polygons;               ///< what triangulating the input's polygon faces found
    bool closed() const { return boundary_edges == 0 && nonmanifold_edges == 0; }
    bool consistently_oriented() const { return inconsistent_edges == 0; }
    /// Why pseudonormal signs are not trustworthy everywhere, "" when they are: the first of
    /// open, non-manifold, inconsistently oriented, several shells, intersections unchecked,
    /// self-intersecting, slivers within the search's rounding. The one rule behind
    /// sign_reliable() and `auto`'s sign (choose_sign_mode), so that the two never disagree.
    std::string sign_unreliable_reason() const;
    /// True when signs from pseudonormals are trustworthy everywhere: `auto` keeps them.
    bool sign_reliable() const { return sign_unreliable_reason().empty(); }
};

/// Float or double copies of a PreparedMesh's arrays, owning what a MeshView points to.
template <typename T>
struct MeshBuffers {
    std::vector<Vec3<T>> vertices, face_normals, edge_normals, vertex_normals;
    std::vector<Int3> triangles;
    DefaultInitVector<PackedTriangle<T>> packed;  ///< every element written by preparation (no zero fill)
    Vec3<T> box_lo{}, box_hi{};  ///< of `vertices` (as converted to T)
    MeshView<T> view() const;
};

/// A prepared mesh is immutable: only prepare_mesh() builds one, with its float and double
/// buffers made at once, so that any number of threads and samplers can share it. Its BVH
/// belongs to it too (bvh()), built once however many samplers and calls use it, as fcpw's
/// Scene::build() and NanoVDB's grids keep their acceleration data with what they describe.
/// Copies share the buffers and the BVH (the same content).
class PreparedMesh {
public:
    const std::string& name() const { return name_; }
    const std::string& source() const { return source_; }                  ///< file path or "shape:NAME"
    const std::string& content_sha256() const { return content_sha256_; }  ///< of the input file or geometry
    const std::vector<Vec3d>& vertices() const { return vertices_; }
    const std::vector<Int3>& triangles() const { return triangles_; }
    /// Index of each triangle in the input's face order.
    const std::vector<int>& source_triangle() const { return source_triangle_; }
    /// The input's vertices and triangles as given to prepare_mesh() (a file's triangulated
    /// faces), the numbering of source_triangle(); empty unless MeshPreparationOptions::keep_input.
    const std::vector<Vec3d>& input_vertices() const { return input_->vertices; }
    const std::vector<Int3>& input_triangles() const { return input_->triangles; }
    const std::vector<Vec3d>& face_normals() const { return face_normals_; }      ///< unit
    /// 3 per triangle, unit; edge e = (v_e, v_(e+1)%3).
    const std::vector<Vec3d>& edge_normals() const { return edge_normals_; }
    const std::vector<Vec3d>& vertex_normals() const { return vertex_normals_; }  ///< unit, angle-weighted
    const MeshReport& report() const { return report_; }
    const Bounds3& bounds() const { return bounds_; }
    /// Edge-connected component (shell) of each triangle, 0-based.
    const std::vector<int>& shell_of() const { return shell_of_; }
    /// Intersecting triangle pairs (prepared-mesh ids, first < second) when checked.
    const std::vector<std::pair<int, int>>& intersecting_triangles() const { return intersecting_triangles_; }

    /// Human-readable warnings (open, non-manifold, inconsistent orientation, flipped).
    std::vector<std::string> warnings() const;

    /// The arrays in precision T (float or double), built with the mesh.
    template <typename T>
    const MeshBuffers<T>& buffers() const;

    /// The float search's per-mesh bound constants (core/bvh/search_bound.h), computed with
    /// the buffers: every certified float search and every tree's build reads them here.
    const FloatSearchBound& search_bound() const { return search_bound_; }

    /// The BVH of the triangles (binned SAH with the default BvhBuildOptions, the one set
    /// every sampler uses; a tree with other options is build_triangle_bvh(mesh, options),
    /// its caller's). Built at most once per mesh and its copies: by prepare_mesh() when it
    /// looks for self-intersections (the same tree), else by the first call. Thread-safe:
    /// concurrent first calls wait for one build. `built_by_this_call` (may be null) tells
    /// whether this call built it, for the samplers' provenance; the tree's stats.seconds
    /// is its build time either way. Throws what build_triangle_bvh throws.
    std::shared_ptr<const TriangleBvh> bvh(bool* built_by_this_call = nullptr) const;

    /// Whether refit_prepared_mesh() can move its vertices (prepared with keep_topology).
    bool refittable() const { return topology_ != nullptr; }

private:
    friend PreparedMesh prepare_mesh(const TriangleMesh& mesh, const MeshPreparationOptions& options);
    friend PreparedMesh refit_prepared_mesh(const PreparedMesh& mesh, const TriangleMesh& moved);
    PreparedMesh() = default;
    struct Topology;  // prepared_mesh.cpp: the face-derived part, shared by a mesh's refits
    std::shared_ptr<const Topology> topology_;

    std::string name_, source_, content_sha256_;
    std::vector<Vec3d> vertices_;
    std::vector<Int3> triangles_;
    std::vector<int> source_triangle_;
    struct InputArrays {
        std::vector<Vec3d> vertices;
        std::vector<Int3> triangles;
    };
    std::shared_ptr<const InputArrays> input_ = std::make_shared<const InputArrays>();
    std::vector<Vec3d> face_normals_, edge_normals_, vertex_normals_;
    std::vector<int> shell_of_;
    std::vector<std::pair<int, int>> intersecting_triangles_;
    MeshReport report_;
    Bounds3 bounds_;
    // Shared, so that copies of a prepared mesh share one set of buffers.
    std::shared_ptr<const MeshBuffers<float>> float_buffers_;
    std::shared_ptr<const MeshBuffers<double>> double_buffers_;
    FloatSearchBound search_bound_;
    /// The BVH, built on first use under the lock; shared by copies like the buffers (a
    /// mutex cannot be copied or moved, a pointer to one can).
    struct BvhSlot {
        std::mutex mutex;
        std::shared_ptr<const TriangleBvh> tree;
    };
    std::shared_ptr<BvhSlot> bvh_slot_ = std::make_shared<BvhSlot>();
};

PreparedMesh prepare_mesh(const TriangleMesh& mesh, const MeshPreparationOptions& options = {});

/// A deforming mesh of the same topology: prepare_mesh(moved, the options `mesh` was prepared
/// with), bit for bit, where `moved` has `mesh`'s input triangles and new positions for its
/// input vertices, without deriving again what the faces alone decide (the welds, the
/// triangles dropped, the edge adjacency, boundary, non-manifold and orientation counts, the
/// shells). The geometry is made again: positions, signed volume, normals and pseudonormals,
/// bounds, buffers, the BVH and the self-intersection check. The outward flip follows the
/// new signed volume, as preparation's. Throws std::invalid_argument, naming the first input
/// vertex or triangle, where the new positions would change that topology (two vertices
/// welded or no longer welded, a triangle newly degenerate or no longer degenerate), or when
/// `mesh` was not prepared with keep_topology or `moved` has other triangles: prepare the
/// moved mesh anew then.
PreparedMesh refit_prepared_mesh(const PreparedMesh& mesh, const TriangleMesh& moved);


}  // namespace sdf
