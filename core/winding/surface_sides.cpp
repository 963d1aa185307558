#include "core/winding/surface_sides.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <utility>

#include "core/parallel/parallel_for.h"
#include "kernels/winding/certified_winding.h"

namespace sdf {
namespace {

struct UnionFind {
    std::vector<int> parent;
    explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
    int find(int x) {
        while (parent[size_t(x)] != x) x = parent[size_t(x)] = parent[size_t(parent[size_t(x)])];
        return x;
    }
    void unite(int a, int b) {
        a = find(a);
        b = find(b);
        if (a != b) parent[size_t(std::max(a, b))] = std::min(a, b);
    }
};

/// The triangles around each vertex, in compressed rows.
struct VertexTriangles {
    std::vector<int64_t> first;  ///< vertices + 1
    std::vector<int> triangle;
    VertexTriangles(size_t vertices, const std::vector<Int3>& tris) : first(vertices + 1, 0), triangle(3 * tris.size()) {
        for (const Int3& t : tris)
            for (int v : {t.x, t.y, t.z}) ++first[size_t(v) + 1];
        std::partial_sum(first.begin(), first.end(), first.begin());
        std::vector<int64_t> next(first.begin(), first.end() - 1);
        for (size_t i = 0; i < tris.size(); ++i)
            for (int v : {tris[i].x, tris[i].y, tris[i].z}) triangle[size_t(next[size_t(v)]++)] = int(i);
    }
};

/// True when the triangles around vertex v form one fan (they connect across their edges
/// through v); a closed mesh's vertex where two fans touch has no single pseudonormal side.
bool one_fan(const VertexTriangles& around, const std::vector<Int3>& tris, int v) {
    const int64_t begin = around.first[size_t(v)], end = around.first[size_t(v) + 1];
    const size_t k = size_t(end - begin);
    thread_local std::vector<std::pair<int, int>> other;  // (the edge's other vertex, local triangle)
    other.clear();
    for (size_t j = 0; j < k; ++j) {
        const Int3 t = tris[size_t(around.triangle[size_t(begin) + j])];
        for (int w : {t.x, t.y, t.z})
            if (w != v) other.emplace_back(w, int(j));
    }
    std::sort(other.begin(), other.end());
    UnionFind fan(k);
    for (size_t i = 1; i < other.size(); ++i)
        if (other[i].first == other[i - 1].first) fan.unite(other[i].second, other[i - 1].second);
    for (size_t j = 1; j < k; ++j)
        if (fan.find(int(j)) != 0) return false;
    return true;
}

/// The certified winding number in front of triangle t, when the direct sum decides it: the
/// sum over every other triangle at t's centroid, less 1/2 (t's own solid angle tends to
/// -2 pi just in front of it), is an integer to within its bound. The sum runs in fixed
/// chunks on `threads` threads, each chunk's rounding bounded as certified_winding_direct()
/// bounds its own, and the chunks added in order with theirs.
bool front_winding_of(const WindingView<double>& v, int t, int threads, int& front) {
    const Int3 tri = v.triangles[t];
    const Vec3d c = (v.vertices[tri.x] + v.vertices[tri.y] + v.vertices[tri.z]) / 3.0;
    constexpr int64_t kChunk = 8192;
    const int64_t n = v.num_triangles, chunks = (n + kChunk - 1) / kChunk;
    std::vector<double> chunk_sum(size_t(chunks), 0.0), chunk_error(size_t(chunks), 0.0);
    parallel_for(chunks, 1, threads, [&](int64_t k0, int64_t k1) {
        for (int64_t k = k0; k < k1; ++k) {
            double s = 0, e = 0;
            for (int64_t i = k * kChunk; i < std::min(n, (k + 1) * kChunk); ++i) {
                if (i == t) continue;
                const Int3 o = v.triangles[i];
                double err;
                s += certified_solid_angle(c, v.vertices[o.x], v.vertices[o.y], v.vertices[o.z], err);
                e += err + kWindingUnitRoundoff * std::fabs(s);
            }
            chunk_sum[size_t(k)] = s;
            chunk_error[size_t(k)] = e;
        }
    });
    double s = 0, e = 0;
    for (int64_t k = 0; k < chunks; ++k) {
        s += chunk_sum[size_t(k)];
        e += chunk_error[size_t(k)] + kWindingUnitRoundoff * std::fabs(s);
    }
    CertifiedSum sum;
    add_solid_angles(sum, s, e);
    const WindingEstimate<double> w = certified_estimate(sum, winding_rounding(v, c), 0);
    const double x = w.value - 0.5, k = std::nearbyint(x);
    const double margin = w.error_bound + 4.0 * kWindingUnitRoundoff * (std::fabs(w.value) + 1.0);
    if (!(std::fabs(x - k) + margin < 0.5) || std::fabs(k) > 127.0) return false;
    front = int(k);
    return true;
}

}  // namespace

SurfaceSides build_surface_sides(const PreparedMesh& mesh, int threads) {
    const auto start = std::chrono::steady_clock::now();
    SurfaceSides out;
    const MeshReport& report = mesh.report();
    const std::vector<Int3>& tris = mesh.triangles();
    if (!report.closed() || !report.consistently_oriented() || !report.intersections_checked || tris.empty()) {
        out.why_off = "the mesh is not closed and consistently oriented with its intersections checked";
        return out;
    }
    const size_t n = tris.size(), nv = mesh.vertices().size();
    // Triangles in an intersecting pair split the regions beside the surface; the corners
    // of such triangles and of slivers, and corners where fans touch, have no single
    // pseudonormal side that can be trusted.
    std::vector<uint8_t> crossed(n, 0), tainted(nv, 0);
    for (const auto& [a, b] : mesh.intersecting_triangles()) crossed[size_t(a)] = crossed[size_t(b)] = 1;
    const VertexTriangles around(nv, tris);
    const std::vector<Vec3d>& x = mesh.vertices();
    std::vector<double> area(n, 0.0);  // twice the area
    for (size_t t = 0; t < n; ++t) {
        const Vec3d a = x[size_t(tris[t].x)], b = x[size_t(tris[t].y)], c = x[size_t(tris[t].z)];
        area[t] = length(cross(b - a, c - a));
        // A sliver's normal is uncertain in direction by about u L^2 / area: its pseudonormals
        // (face, edges and corners) do not vouch for a side.
        const double longest = std::max({length_squared(b - a), length_squared(c - b), length_squared(a - c)});
        if (crossed[t] || !(area[t] > std::ldexp(longest, -30)))
            for (int v : {tris[t].x, tris[t].y, tris[t].z}) tainted[size_t(v)] = 1;
    }
    std::vector<uint8_t> fan_ok(nv, 1);
    parallel_for(int64_t(nv), 4096, threads, [&](int64_t v0, int64_t v1) {
        for (int64_t v = v0; v < v1; ++v) fan_ok[size_t(v)] = one_fan(around, tris, int(v));
    });
    for (size_t v = 0; v < nv; ++v) tainted[v] |= !fan_ok[v];

    // Components of the uncrossed triangles across their (manifold) edges: the region in
    // front of one is the region in front of all.
    UnionFind components(n);
    for (size_t t = 0; t < n; ++t) {
        if (crossed[t]) continue;
        const int c[3] = {tris[t].x, tris[t].y, tris[t].z};
        for (int e = 0; e < 3; ++e) {
            const int a = c[e], b = c[(e + 1) % 3];
            for (int64_t j = around.first[size_t(a)]; j < around.first[size_t(a) + 1]; ++j) {
                const int u = around.triangle[size_t(j)];
                if (size_t(u) == t || crossed[size_t(u)]) continue;
                const Int3 o = tris[size_t(u)];
                if (o.x == b || o.y == b || o.z == b) components.unite(int(t), u);
            }
        }
    }
    // Each component's candidates: its safe triangles, largest first (their centroids lie
    // farthest from the other triangles' planes).
    std::vector<int> root(n), size_of(n, 0);
    for (size_t t = 0; t < n; ++t) {
        root[t] = crossed[t] ? -1 : components.find(int(t));
        if (root[t] >= 0) ++size_of[size_t(root[t])];
    }
    std::vector<int> roots;
    for (size_t t = 0; t < n; ++t)
        if (root[t] == int(t)) roots.push_back(int(t));
    out.components = int(roots.size());
    std::stable_sort(roots.begin(), roots.end(), [&](int a, int b) { return size_of[size_t(a)] > size_of[size_t(b)]; });
    if (roots.size() > size_t(kSurfaceSideComponents)) roots.resize(size_t(kSurfaceSideComponents));
    constexpr int kCandidates = 3;
    std::vector<std::vector<int>> candidates(n > 0 ? roots.size() : 0);
    std::vector<int> slot_of(n, -1);
    for (size_t r = 0; r < roots.size(); ++r) slot_of[size_t(roots[r])] = int(r);
    for (size_t t = 0; t < n; ++t) {
        if (root[t] < 0 || slot_of[size_t(root[t])] < 0) continue;
        const Int3 tri = tris[t];
        if (tainted[size_t(tri.x)] || tainted[size_t(tri.y)] || tainted[size_t(tri.z)]) continue;
        std::vector<int>& c = candidates[size_t(slot_of[size_t(root[t])])];
        c.push_back(int(t));
        std::sort(c.begin(), c.end(), [&](int a, int b) { return area[size_t(a)] > area[size_t(b)] || (area[size_t(a)] == area[size_t(b)] && a < b); });
        if (c.size() > size_t(kCandidates)) c.pop_back();
    }

    WindingView<double> view;
    view.vertices = x.data();
    view.triangles = tris.data();
    view.num_triangles = int(n);
    view.scale = 0;
    for (const Vec3d& p : x) view.scale = std::max(view.scale, std::max(std::fabs(p.x), std::max(std::fabs(p.y), std::fabs(p.z))));
    std::vector<int> front(roots.size(), int(kSurfaceSideUnknown));
    for (size_t r = 0; r < roots.size(); ++r)
        for (int t : candidates[r]) {
            int w = 0;
            if (front_winding_of(view, t, threads, w)) {
                front[r] = w;
                break;
            }
        }
    out.front_winding.assign(n, kSurfaceSideUnknown);
    for (size_t t = 0; t < n; ++t) {
        if (root[t] < 0 || slot_of[size_t(root[t])] < 0) continue;
        const Int3 tri = tris[t];
        if (tainted[size_t(tri.x)] || tainted[size_t(tri.y)] || tainted[size_t(tri.z)]) continue;
        const int w = front[size_t(slot_of[size_t(root[t])])];
        if (w == int(kSurfaceSideUnknown)) continue;
        out.front_winding[t] = int8_t(w);
        ++out.triangles_known;
    }
    for (int w : front) out.components_decided += w != int(kSurfaceSideUnknown);
    // Below this distance the pseudonormal's side is within rounding of the surface: the
    // ladder's tie rule decides there, as it would without the table.
    out.min_distance = std::ldexp(view.scale, -36);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

}  // namespace sdf
