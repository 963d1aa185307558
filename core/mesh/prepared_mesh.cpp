#include "core/mesh/prepared_mesh.h"

#include <algorithm>
#include <atomic>
#include <future>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "core/bvh/search_bound.h"
#include "core/bvh/triangle_bvh.h"
#include "core/mesh/exact_predicates.h"
#include "core/mesh/self_intersections.h"
#include "core/mesh/vertex_welding.h"
#include "core/parallel/parallel_for.h"
#include "core/parallel/task_monitor.h"
#include "kernels/distance/accurate_cross.h"

namespace sdf {
namespace {

constexpr double kPi = 3.14159265358979323846;

double corner_angle(const Vec3d& at, const Vec3d& a, const Vec3d& b) {
    const Vec3d u = normalize_or_zero(a - at), v = normalize_or_zero(b - at);
    return std::atan2(length(cross(u, v)), dot(u, v));
}

struct EdgeUse {
    int triangle;
    int local_edge;
    bool forward;  ///< traversed from the lower vertex id to the higher one
};

/// Every edge's uses, in the order a std::map from (smaller, larger) vertex id to the uses in
/// triangle order would give them, without a node and a vector per edge: one array of uses
/// ordered by edge. for_each(fn) calls fn(uses, count) once per edge.
///
/// The order is a stable sort by (smaller, larger) id, made as a counting sort by the smaller
/// id (a pass in triangle order, so each vertex's uses stay in triangle order) and then an
/// insertion sort of each vertex's few uses by the larger id (stable too): O(n) instead of
/// a merge sort of 3n keys.
class EdgeUses {
public:
    EdgeUses(const std::vector<Int3>& triangles, int num_vertices, int threads) {
        const size_t n = 3 * triangles.size();
        std::vector<size_t> start(size_t(num_vertices) + 1, 0);  // size_t: 3 uses a triangle
        for (const Int3& t : triangles)
            for (int e = 0; e < 3; ++e) ++start[size_t(std::min(t[e], t[(e + 1) % 3])) + 1];
        for (size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
        std::vector<Sorted> sorted(n);
        std::vector<size_t> next(start.begin(), start.end() - 1);
        for (size_t i = 0; i < triangles.size(); ++i)
            for (int e = 0; e < 3; ++e) {
                const int a = triangles[i][e], b = triangles[i][(e + 1) % 3];
                sorted[next[size_t(std::min(a, b))]++] = {std::max(a, b), {int(i), e, a < b}};
            }
        // Each vertex's uses by the larger id (stable), then the edges' first uses. A vertex
        // has a handful of uses; one shared by many (a fan's centre) gets a merge sort.
        parallel_for(num_vertices, 4096, threads, [&](int64_t v0, int64_t v1) {
            for (int64_t v = v0; v < v1; ++v) {
                const size_t lo = start[size_t(v)], hi = start[size_t(v) + 1];
                if (hi - lo > 32) {
                    std::stable_sort(sorted.begin() + ptrdiff_t(lo), sorted.begin() + ptrdiff_t(hi),
                                     [](const Sorted& a, const Sorted& b) { return a.other < b.other; });
                    continue;
                }
                for (size_t k = lo + 1; k < hi; ++k) {
                    const Sorted x = sorted[k];
                    size_t j = k;
                    for (; j > lo && sorted[j - 1].other > x.other; --j) sorted[j] = sorted[j - 1];
                    sorted[j] = x;
                }
            }
        });
        uses_.resize(n);
        first_.reserve(n / 2 + 1);
        for (int v = 0; v < num_vertices; ++v)
            for (size_t k = start[size_t(v)]; k < start[size_t(v) + 1]; ++k) {
                if (k == start[size_t(v)] || sorted[k].other != sorted[k - 1].other) first_.push_back(k);
                uses_[k] = sorted[k].use;
            }
        first_.push_back(n);
    }

    template <class Fn>
    void for_each(Fn fn) const {
        for (size_t g = 0; g + 1 < first_.size(); ++g) fn(&uses_[first_[g]], first_[g + 1] - first_[g]);
    }

    /// fn(uses, count) for every edge, on `threads` threads: for work that writes only the
    /// edge's own uses.
    template <class Fn>
    void parallel_for_each(int threads, Fn fn) const {
        parallel_for(int64_t(first_.size()) - 1, 4096, threads, [&](int64_t g0, int64_t g1) {
            for (int64_t g = g0; g < g1; ++g) fn(&uses_[first_[size_t(g)]], first_[size_t(g) + 1] - first_[size_t(g)]);
        });
    }

private:
    struct Sorted {
        int other;  ///< the edge's larger vertex id
        EdgeUse use;
    };
    std::vector<EdgeUse> uses_;
    std::vector<size_t> first_;  ///< where each edge's uses begin, and the end
};

int find_root(std::vector<int>& parent, int i) {
    while (parent[size_t(i)] != i) i = parent[size_t(i)] = parent[size_t(parent[size_t(i)])];
    return i;
}

}  // namespace

namespace {
template <typename T>
std::vector<Vec3<T>> convert(const std::vector<Vec3d>& in, int threads) {
    std::vector<Vec3<T>> out(in.size());
    parallel_for(int64_t(in.size()), 16384, threads, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) out[size_t(i)] = Vec3<T>(in[size_t(i)]);
    });
    return out;
}

template <typename T>
std::shared_ptr<MeshBuffers<T>> make_buffers(const PreparedMesh& m, int threads) {
    auto b = std::make_shared<MeshBuffers<T>>();
    b->vertices = convert<T>(m.vertices(), threads);
    b->face_normals = convert<T>(m.face_normals(), threads);
    b->edge_normals = convert<T>(m.edge_normals(), threads);
    b->vertex_normals = convert<T>(m.vertex_normals(), threads);
    b->triangles = m.triangles();
    if (!b->vertices.empty()) b->box_lo = b->box_hi = b->vertices.front();
    for (const Vec3<T>& v : b->vertices) {
        b->box_lo = {std::min(b->box_lo.x, v.x), std::min(b->box_lo.y, v.y), std::min(b->box_lo.z, v.z)};
        b->box_hi = {std::max(b->box_hi.x, v.x), std::max(b->box_hi.y, v.y), std::max(b->box_hi.z, v.z)};
    }
    b->packed.resize(m.triangles().size());
    parallel_for(int64_t(m.triangles().size()), 8192, threads, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) {
            const Int3 t = m.triangles()[size_t(i)];
            b->packed[size_t(i)] = pack_triangle<T>(m.vertices()[size_t(t.x)], m.vertices()[size_t(t.y)], m.vertices()[size_t(t.z)]);
        }
    });
    return b;
}
}  // namespace

/// What preparation derives from the faces alone, kept with keep_topology and shared by a
/// mesh's refits: refit_prepared_mesh() checks the welds and dropped triangles against it and
/// reuses the edge adjacency. Its static members are preparation's passes that both
/// prepare_mesh() and refit_prepared_mesh() run (a nested class sees the mesh's own fields).
struct PreparedMesh::Topology {
    MeshPreparationOptions options;
    std::vector<Int3> input_triangles;  ///< as given to prepare_mesh()
    std::vector<int> weld;              ///< input vertex -> welded vertex (weld_vertices' remap)
    std::vector<uint8_t> degenerate;    ///< per input triangle: dropped
    std::vector<int> welded_of;         ///< prepared vertex -> its welded vertex
    EdgeUses edges;                     ///< of the triangles as oriented (PreparedMesh::triangles())

    /// The signed volume of the triangles (summed in triangle order) and, where the mesh is
    /// closed and consistent, the outward flip; true when the triangles were flipped.
    static bool orient(PreparedMesh& out, const MeshPreparationOptions& options);
    /// Everything the positions decide, given the triangles and their edges: pseudonormals,
    /// bounds, buffers, the float search's bound, the BVH and the self-intersection check.
    static void make_geometry(PreparedMesh& out, const EdgeUses& edges, const MeshPreparationOptions& options, int threads);
};

namespace {

Int3 welded_triangle(const std::vector<int>& weld, const Int3& t) {
    return {weld[size_t(t.x)], weld[size_t(t.y)], weld[size_t(t.z)]};
}

/// Per input triangle: dropped, for a repeated vertex or exactly collinear corners (decided in
/// exact arithmetic: a rounded cross product of collinear points need not be 0; the
/// intersection predicates need a plane per triangle).
std::vector<uint8_t> degenerate_triangles(const std::vector<Int3>& triangles, const std::vector<int>& weld,
                                          const std::vector<Vec3d>& welded, int threads) {
    std::vector<uint8_t> degenerate(triangles.size());
    parallel_for(int64_t(triangles.size()), 8192, threads, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) {
            const Int3 w = welded_triangle(weld, triangles[size_t(i)]);
            degenerate[size_t(i)] = w.x == w.y || w.y == w.z || w.z == w.x ||
                                    exact::collinear(welded[size_t(w.x)], welded[size_t(w.y)], welded[size_t(w.z)]);
        }
    });
    return degenerate;
}

/// Triangles whose height over their longest edge (the accurate cross product's length over
/// it) is below kRoundingSliverHeight of the mesh's largest extent.
int count_slivers_within_rounding(const std::vector<Vec3d>& v, const std::vector<Int3>& triangles, const Bounds3& bounds,
                                  int threads) {
    if (triangles.empty()) return 0;
    const Vec3d e = bounds.extent();
    const double limit = kRoundingSliverHeight * std::max({e.x, e.y, e.z});
    std::atomic<int> count{0};
    parallel_for(int64_t(triangles.size()), 8192, threads, [&](int64_t i0, int64_t i1) {
        int n = 0;
        for (int64_t i = i0; i < i1; ++i) {
            const Int3 t = triangles[size_t(i)];
            const Vec3d &a = v[size_t(t.x)], &b = v[size_t(t.y)], &c = v[size_t(t.z)];
            const double longest = std::sqrt(std::max({length_squared(b - a), length_squared(c - b), length_squared(a - c)}));
            n += length(accurate_triangle_cross(a, b, c)) < limit * longest ? 1 : 0;
        }
        count += n;
    });
    return count.load();
}

}  // namespace

bool PreparedMesh::Topology::orient(PreparedMesh& out, const MeshPreparationOptions& options) {
    MeshReport& rep = out.report_;
    rep.signed_volume = 0;
    for (const Int3& t : out.triangles_)
        rep.signed_volume += dot(out.vertices_[size_t(t.x)],
                                 cross(out.vertices_[size_t(t.y)], out.vertices_[size_t(t.z)])) / 6.0;
    rep.flipped = options.orient_outward && rep.closed() && rep.consistently_oriented() && rep.signed_volume < 0;
    if (rep.flipped) {
        for (Int3& t : out.triangles_) std::swap(t.y, t.z);
        rep.signed_volume = -rep.signed_volume;
    }
    return rep.flipped;
}

void PreparedMesh::Topology::make_geometry(PreparedMesh& out, const EdgeUses& edges, const MeshPreparationOptions& options,
                                           int threads) {
    MeshReport& rep = out.report_;
    // Angle-weighted pseudonormals.
    const size_t nt = out.triangles_.size();
    out.face_normals_.resize(nt);
    out.edge_normals_.resize(3 * nt);
    out.vertex_normals_.assign(out.vertices_.size(), Vec3d(0.0));
    // Each triangle's normal and corner weights on every thread; the vertex normals are then
    // summed in triangle order, as one pass would (the same bits).
    std::vector<Vec3d> corner_weights(nt);
    parallel_for(int64_t(nt), 8192, threads, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) {
            const Int3 t = out.triangles_[size_t(i)];
            const Vec3d& a = out.vertices_[size_t(t.x)];
            const Vec3d& b = out.vertices_[size_t(t.y)];
            const Vec3d& c = out.vertices_[size_t(t.z)];
            out.face_normals_[size_t(i)] = normalize_or_zero(cross(b - a, c - a));
            corner_weights[size_t(i)] = {corner_angle(a, b, c), corner_angle(b, c, a), corner_angle(c, a, b)};
        }
    });
    for (size_t i = 0; i < nt; ++i) {
        const Int3 t = out.triangles_[i];
        const Vec3d n = out.face_normals_[i];
        out.vertex_normals_[size_t(t.x)] += n * corner_weights[i].x;
        out.vertex_normals_[size_t(t.y)] += n * corner_weights[i].y;
        out.vertex_normals_[size_t(t.z)] += n * corner_weights[i].z;
    }
    parallel_for(int64_t(out.vertex_normals_.size()), 16384, threads, [&](int64_t v0, int64_t v1) {
        for (int64_t v = v0; v < v1; ++v) out.vertex_normals_[size_t(v)] = normalize_or_zero(out.vertex_normals_[size_t(v)]);
    });
    // Every use of a triangle's edge is one edge's: each edge writes only its own uses.
    edges.parallel_for_each(threads, [&](const EdgeUse* uses, size_t count) {
        // Each incident face contributes its normal with weight pi (the angle of a face
        // around an edge); for a manifold edge this is the normalised sum of both normals.
        Vec3d sum(0.0);
        for (size_t u = 0; u < count; ++u) sum += out.face_normals_[size_t(uses[u].triangle)] * kPi;
        const Vec3d n = normalize_or_zero(sum);
        for (size_t u = 0; u < count; ++u)
            out.edge_normals_[3 * size_t(uses[u].triangle) + size_t(uses[u].local_edge)] =
                length_squared(n) > 0 ? n : out.face_normals_[size_t(uses[u].triangle)];
    });
    out.bounds_ = triangle_bounds(out.vertices_, out.triangles_);
    rep.slivers_within_rounding = count_slivers_within_rounding(out.vertices_, out.triangles_, out.bounds_, threads);
    {
        // The two precisions' buffers at once, each pass on every thread.
        std::future<std::shared_ptr<MeshBuffers<float>>> floats =
            std::async(std::launch::async, [&, monitor = current_task_monitor()] {
                const ScopedTaskMonitor scope(monitor);  // the caller's stop requests
                return make_buffers<float>(out, threads);
            });
        out.double_buffers_ = make_buffers<double>(out, threads);
        out.float_buffers_ = floats.get();
    }
    out.search_bound_ =
        float_search_bound(out.vertices_, out.triangles_, out.double_buffers_->packed, out.float_buffers_->packed, threads);

    rep.intersections_checked = false;
    rep.self_intersecting_pairs = rep.shell_intersecting_pairs = rep.overlapping_shells = 0;
    if (options.detect_intersections && !out.triangles_.empty()) {
        // The samplers' tree (the same build): kept, so that the mesh's BVH is built once.
        BvhBuildOptions tree;
        tree.threads = threads;
        out.bvh_slot_->tree = std::make_shared<const TriangleBvh>(build_triangle_bvh(out, tree));
        const SelfIntersections found = find_self_intersections(out, *out.bvh_slot_->tree, out.shell_of_, threads);
        out.intersecting_triangles_ = found.pairs;
        rep.intersections_checked = true;
        rep.self_intersecting_pairs = found.within_shell;
        rep.shell_intersecting_pairs = found.between_shells;
        rep.overlapping_shells = found.overlapping_shell_pairs;
    }
}

PreparedMesh prepare_mesh(const TriangleMesh& mesh, const MeshPreparationOptions& options) {
    PreparedMesh out;
    out.name_ = mesh.name;
    out.source_ = mesh.source;
    out.content_sha256_ = mesh.content_sha256.empty() ? geometry_sha256(mesh) : mesh.content_sha256;
    MeshReport& rep = out.report_;
    rep.input_vertices = int(mesh.vertices.size());
    rep.input_triangles = int(mesh.triangles.size());
    rep.polygons = mesh.polygon_stats;
    if (options.keep_input) out.input_ = std::make_shared<const PreparedMesh::InputArrays>(PreparedMesh::InputArrays{mesh.vertices, mesh.triangles});

    // Weld, then drop triangles with a repeated vertex or exactly zero area.
    std::vector<Vec3d> welded;
    const std::vector<int> remap = weld_vertices(mesh.vertices, options.weld_tolerance, welded);
    rep.welded_vertices = int(mesh.vertices.size() - welded.size());
    const int threads = resolve_thread_count(options.threads);
    const int64_t input_triangles = int64_t(mesh.triangles.size());
    const std::vector<uint8_t> degenerate = degenerate_triangles(mesh.triangles, remap, welded, threads);
    std::vector<Int3> tris;
    tris.reserve(size_t(input_triangles));
    out.source_triangle_.reserve(size_t(input_triangles));
    for (int64_t i = 0; i < input_triangles; ++i) {
        if (degenerate[size_t(i)]) {
            ++rep.degenerate_triangles;
            continue;
        }
        tris.push_back(welded_triangle(remap, mesh.triangles[size_t(i)]));
        out.source_triangle_.push_back(int(i));
    }

    // Nothing left to measure distance to: every sampler, BVH and lattice fit downstream
    // assumes at least one triangle, so refuse here, where the file can still be named.
    if (tris.empty())
        throw std::runtime_error((mesh.source.empty() ? mesh.name : mesh.source) + ": no triangle left: all " +
                                 std::to_string(mesh.triangles.size()) +
                                 " triangles are degenerate (repeated vertex or zero area); expected at least one "
                                 "triangle with three distinct, non-collinear vertices");

    // Compact away unreferenced vertices.
    std::vector<int> used(welded.size(), -1), welded_of;
    for (Int3& t : tris)
        for (int k = 0; k < 3; ++k) {
            int& id = used[size_t(t[k])];
            if (id < 0) {
                id = int(out.vertices_.size());
                out.vertices_.push_back(welded[size_t(t[k])]);
                welded_of.push_back(t[k]);
            }
            t[k] = id;
        }
    rep.unreferenced_vertices = int(welded.size() - out.vertices_.size());
    out.triangles_ = std::move(tris);

    // Edge adjacency: boundary, non-manifold and orientation checks; components.
    EdgeUses edges(out.triangles_, int(out.vertices_.size()), threads);
    std::vector<int> parent(out.triangles_.size());
    std::iota(parent.begin(), parent.end(), 0);
    edges.for_each([&](const EdgeUse* uses, size_t count) {
        if (count == 1) ++rep.boundary_edges;
        if (count > 2) ++rep.nonmanifold_edges;
        if (count == 2 && uses[0].forward == uses[1].forward) ++rep.inconsistent_edges;
        for (size_t u = 1; u < count; ++u)
            parent[size_t(find_root(parent, uses[u].triangle))] = find_root(parent, uses[0].triangle);
    });
    out.shell_of_.assign(parent.size(), -1);
    std::vector<int> shell_of_root(parent.size(), -1);
    for (size_t i = 0; i < parent.size(); ++i) {
        int& shell = shell_of_root[size_t(find_root(parent, int(i)))];
        if (shell < 0) shell = rep.components++;
        out.shell_of_[i] = shell;
    }

    // Orientation: make a closed, consistent mesh point outward. Edge e of a flipped triangle
    // is a different edge: the adjacency lookups are made again.
    using Topology = PreparedMesh::Topology;
    if (Topology::orient(out, options)) edges = EdgeUses(out.triangles_, int(out.vertices_.size()), threads);
    Topology::make_geometry(out, edges, options, threads);
    if (options.keep_topology)
        out.topology_ = std::make_shared<const Topology>(
            Topology{options, mesh.triangles, remap, degenerate, std::move(welded_of), std::move(edges)});
    return out;
}

namespace {

[[noreturn]] void refuse_refit(const PreparedMesh& mesh, const std::string& why) {
    throw std::invalid_argument("refit of mesh '" + mesh.name() + "': " + why +
                                "; refit keeps the topology of the mesh's first preparation: prepare the moved mesh anew");
}

/// What welding did with input vertex i, for messages.
std::string weld_fate(const std::vector<int>& weld, size_t i) {
    size_t first = 0;
    while (weld[first] != weld[i]) ++first;
    return first == i ? "a vertex of its own" : "welded to input vertex " + std::to_string(first);
}

}  // namespace

PreparedMesh refit_prepared_mesh(const PreparedMesh& mesh, const TriangleMesh& moved) {
    if (!mesh.topology_) refuse_refit(mesh, "it was prepared without keep_topology");
    const PreparedMesh::Topology& topo = *mesh.topology_;
    const MeshPreparationOptions& options = topo.options;
    if (moved.vertices.size() != topo.weld.size())
        refuse_refit(mesh, "expected " + std::to_string(topo.weld.size()) + " vertices (one per input vertex), got " +
                               std::to_string(moved.vertices.size()));
    if (moved.triangles != topo.input_triangles) refuse_refit(mesh, "the triangles differ from the input's");
    const int threads = resolve_thread_count(options.threads);

    // The welds and the dropped triangles must be the ones a preparation of the new
    // positions makes. With tolerance 0 that is checked without the welding's map of lists
    // (welds_like); else, and to say how they differ, the welding runs and is compared.
    std::vector<Vec3d> welded;
    std::vector<int> remap;
    if (options.weld_tolerance == 0 && welds_like(moved.vertices, topo.weld, welded, threads))
        remap = topo.weld;
    else
        remap = weld_vertices(moved.vertices, options.weld_tolerance, welded = {});
    const auto differs = std::mismatch(remap.begin(), remap.end(), topo.weld.begin());
    if (differs.first != remap.end()) {
        const size_t i = size_t(differs.first - remap.begin());
        std::ostringstream tolerance;
        tolerance << options.weld_tolerance;
        refuse_refit(mesh, "input vertex " + std::to_string(i) + " was " + weld_fate(topo.weld, i) +
                               " when the mesh was prepared and is " + weld_fate(remap, i) +
                               " at the new positions (weld_tolerance " + tolerance.str() + ")");
    }
    const std::vector<uint8_t> degenerate = degenerate_triangles(moved.triangles, remap, welded, threads);
    const auto changed = std::mismatch(degenerate.begin(), degenerate.end(), topo.degenerate.begin());
    if (changed.first != degenerate.end()) {
        const size_t t = size_t(changed.first - degenerate.begin());
        refuse_refit(mesh, "input triangle " + std::to_string(t) + (*changed.first ? " is" : " is not") +
                               " degenerate (collinear corners) at the new positions and" +
                               (*changed.first ? " was not" : " was") + " when the mesh was prepared");
    }

    PreparedMesh out;
    out.name_ = moved.name;
    out.source_ = moved.source;
    out.content_sha256_ = moved.content_sha256.empty() ? geometry_sha256(moved) : moved.content_sha256;
    if (options.keep_input) out.input_ = std::make_shared<const PreparedMesh::InputArrays>(PreparedMesh::InputArrays{moved.vertices, moved.triangles});
    // The face-derived counts are the first preparation's; the positions' are made below.
    out.report_ = mesh.report_;
    out.report_.polygons = moved.polygon_stats;
    out.source_triangle_ = mesh.source_triangle_;
    out.shell_of_ = mesh.shell_of_;
    out.vertices_.resize(topo.welded_of.size());
    for (size_t v = 0; v < topo.welded_of.size(); ++v) out.vertices_[v] = welded[size_t(topo.welded_of[v])];
    out.triangles_ = mesh.triangles_;
    if (mesh.report_.flipped)  // back to the input's orientation, which preparation orients
        for (Int3& t : out.triangles_) std::swap(t.y, t.z);
    if (PreparedMesh::Topology::orient(out, options) == mesh.report_.flipped) {
        out.topology_ = mesh.topology_;
    } else {  // turned inside out: the flip differs, and so the triangles' edges
        PreparedMesh::Topology flipped{options, topo.input_triangles, topo.weld, topo.degenerate, topo.welded_of,
                                       EdgeUses(out.triangles_, int(out.vertices_.size()), threads)};
        out.topology_ = std::make_shared<const PreparedMesh::Topology>(std::move(flipped));
    }
    PreparedMesh::Topology::make_geometry(out, out.topology_->edges, options, threads);
    return out;
}

std::string MeshReport::sign_unreliable_reason() const {
    if (boundary_edges > 0) return "the mesh is open (" + std::to_string(boundary_edges) + " boundary edges)";
    if (nonmanifold_edges > 0) return "the mesh has " + std::to_string(nonmanifold_edges) + " non-manifold edges";
    if (inconsistent_edges > 0)
        return "the mesh is not consistently oriented (" + std::to_string(inconsistent_edges) + " edges)";
    if (components > 1) return "the mesh has " + std::to_string(components) + " shells";
    if (!intersections_checked) return "self-intersections were not checked";
    if (self_intersecting_pairs > 0)
        return "the mesh intersects itself (" + std::to_string(self_intersecting_pairs) + " triangle pairs)";
    if (slivers_within_rounding > 0)
        return "the mesh has " + std::to_string(slivers_within_rounding) +
               " slivers thinner than the nearest-triangle search's rounding (their nearest edge is not decided)";
    return "";
}

std::vector<std::string> PreparedMesh::warnings() const {
    std::vector<std::string> w;
    const std::string who = "mesh '" + name_ + "' (" + source_ + ")";
    if (report_.boundary_edges > 0)
        w.push_back(who + " is open: " + std::to_string(report_.boundary_edges) +
                    " boundary edges. Distances are exact, but the sign is only the side of the "
                    "nearest surface feature (negative = behind its pseudonormal); near and "
                    "through the holes 'inside' and 'outside' are not defined.");
    if (report_.nonmanifold_edges > 0)
        w.push_back(who + " has " + std::to_string(report_.nonmanifold_edges) +
                    " non-manifold edges (used by more than two triangles); signs next to them "
                    "may be wrong.");
    if (report_.inconsistent_edges > 0)
        w.push_back(who + " is not consistently oriented (" + std::to_string(report_.inconsistent_edges) +
                    " edges traversed twice in the same direction); pseudonormal signs are "
                    "unreliable near those edges.");
    if (report_.self_intersecting_pairs > 0)
        w.push_back(who + " intersects itself: " + std::to_string(report_.self_intersecting_pairs) +
                    " triangle pairs cross within a shell; pseudonormal signs are wrong in the regions they enclose "
                    "twice (use the winding-number sign).");
    if (report_.slivers_within_rounding > 0)
        w.push_back(who + " has " + std::to_string(report_.slivers_within_rounding) +
                    " slivers thinner than the nearest-triangle search's rounding; pseudonormal signs may take a "
                    "neighbouring edge's side beside them (auto uses the winding-number sign).");
    if (report_.overlapping_shells > 0)
        w.push_back(who + " has " + std::to_string(report_.overlapping_shells) + " pairs of overlapping shells (" +
                    std::to_string(report_.shell_intersecting_pairs) +
                    " intersecting triangle pairs); pseudonormal signs are wrong where one shell is inside another "
                    "(use the winding-number sign).");
    if (report_.polygons.non_planar > 0) {
        std::ostringstream deviation;
        deviation.precision(2);
        deviation << report_.polygons.max_non_planarity;
        w.push_back(who + " has " + std::to_string(report_.polygons.non_planar) +
                    " non-planar polygons (corners up to " + deviation.str() +
                    " of a polygon's size off its best-fit plane). Each was cut into triangles in its best-fit "
                    "plane, shortest cut first; near them the surface, and so distances and signs, depend on "
                    "that choice.");
    }
    if (report_.polygons.not_simple > 0)
        w.push_back(who + " has " + std::to_string(report_.polygons.not_simple) +
                    " polygons that cross themselves or have no area in their best-fit plane; their triangles "
                    "may overlap.");
    if (report_.flipped)
        w.push_back(who + " was oriented inward (negative signed volume); all triangles were flipped.");
    if (report_.degenerate_triangles > 0)
        w.push_back(who + ": dropped " + std::to_string(report_.degenerate_triangles) +
                    " degenerate triangles (repeated vertex or zero area).");
    return w;
}

template <typename T>
MeshView<T> MeshBuffers<T>::view() const {
    MeshView<T> v;
    v.vertices = vertices.data();
    v.triangles = triangles.data();
    v.face_normals = face_normals.data();
    v.edge_normals = edge_normals.data();
    v.vertex_normals = vertex_normals.data();
    v.packed = packed.data();
    v.num_triangles = int(triangles.size());
    v.num_vertices = int(vertices.size());
    v.box_lo = box_lo;
    v.box_hi = box_hi;
    return v;
}


std::shared_ptr<const TriangleBvh> PreparedMesh::bvh(bool* built_by_this_call) const {
    std::lock_guard<std::mutex> lock(bvh_slot_->mutex);
    const bool build = !bvh_slot_->tree;
    if (build) bvh_slot_->tree = std::make_shared<const TriangleBvh>(build_triangle_bvh(*this));
    if (built_by_this_call) *built_by_this_call = build;
    return bvh_slot_->tree;
}

template <>
const MeshBuffers<float>& PreparedMesh::buffers<float>() const {
    return *float_buffers_;
}
template <>
const MeshBuffers<double>& PreparedMesh::buffers<double>() const {
    return *double_buffers_;
}

template struct MeshBuffers<float>;
template struct MeshBuffers<double>;

}  // namespace sdf
