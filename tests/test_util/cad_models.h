// CAD-like test models: closed orthogonal solids (boxes, plates, an L, a frame with a hole,
// stairs) whose planar faces are split into rectangular panels and triangulated as a CAD
// exporter does: long fans from a corner, fans from the panel's centre and zigzag strips, over
// edges subdivided into collinear points shared with the neighbouring panel (coplanar or not).
// Every panel edge is shared by exactly two panels, so the meshes are closed, manifold,
// outward oriented, one shell, and have no self-intersection: any pair a check reports is a
// false positive. Placements put the grid (integer units) in the world at several scales,
// offsets and rotations, keeping collinear points exactly collinear (axis-aligned, or rotated
// with few-bit axes so that every coordinate is exact) or rounding them as a file would.
// Used by tests/core/mesh (against CGAL) and tests/core/winding (the sign of `auto`).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/mesh/triangle_mesh.h"

namespace sdf::test {

/// The occupied cells of a rectilinear grid; line positions are multiples of 12 grid units, so
/// that edges split into 1, 2, 3, 4 or 6 parts have integer points.
struct CadSolid {
    std::string name;
    std::array<std::vector<int>, 3> lines;
    std::vector<std::array<int, 3>> cells;  ///< occupied (i, j, k)

    bool occupied(int i, int j, int k) const {
        for (const auto& c : cells)
            if (c[0] == i && c[1] == j && c[2] == k) return true;
        return false;
    }
};

inline std::vector<CadSolid> cad_solids() {
    std::vector<CadSolid> s;
    s.push_back({"box", {{{0, 36, 48}, {0, 24, 36}, {0, 24}}}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}});
    CadSolid plate{"plate", {{{0, 60, 96, 120}, {0, 48, 84}, {0, 12}}}, {}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 2; ++j) plate.cells.push_back({i, j, 0});
    s.push_back(plate);
    s.push_back({"l_shape", {{{0, 24, 72}, {0, 24, 60}, {0, 36}}}, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}});
    CadSolid frame{"frame", {{{0, 24, 48, 72}, {0, 24, 48, 72}, {0, 12}}}, {}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (i != 1 || j != 1) frame.cells.push_back({i, j, 0});
    s.push_back(frame);
    CadSolid stairs{"stairs", {{{0, 36, 72, 108}, {0, 48}, {0, 24, 48, 72}}}, {}};
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3 - i; ++k) stairs.cells.push_back({i, 0, k});
    s.push_back(stairs);
    return s;
}

/// world = offset + axes[0] * g.x + axes[1] * g.y + axes[2] * g.z for a grid point g.
struct CadPlacement {
    std::string label;
    std::array<Vec3d, 3> axes;
    Vec3d offset;
    Vec3d apply(const Vec3d& g) const {
        const Vec3d linear = axes[0] * g.x + axes[1] * g.y + axes[2] * g.z;
        return offset + linear;
    }
};

/// The rotation about (1, 2, 3) by 0.7 radians; `bits` > 0 rounds its entries to multiples of
/// 2^-bits, so that with integer grid points every product and sum is exact.
inline std::array<Vec3d, 3> cad_rotation(int bits) {
    const Vec3d a = normalize_or_zero(Vec3d{1, 2, 3});
    const double c = std::cos(0.7), s = std::sin(0.7), t = 1 - c;
    std::array<Vec3d, 3> r = {Vec3d{t * a.x * a.x + c, t * a.x * a.y + s * a.z, t * a.x * a.z - s * a.y},
                              Vec3d{t * a.x * a.y - s * a.z, t * a.y * a.y + c, t * a.y * a.z + s * a.x},
                              Vec3d{t * a.x * a.z + s * a.y, t * a.y * a.z - s * a.x, t * a.z * a.z + c}};
    if (bits > 0)
        for (Vec3d& col : r)
            for (int k = 0; k < 3; ++k) col[k] = std::ldexp(std::round(std::ldexp(col[k], bits)), -bits);
    return r;
}

/// Scales 1e-3 .. 1e3 and offsets up to 1e4: axis-aligned (any scale keeps collinear points
/// collinear), rotated with 26-bit axes and power-of-two scales (exactly collinear, but the
/// orientation determinants round), and rotated in full double (rounded like a file).
inline std::vector<CadPlacement> cad_placements() {
    std::vector<CadPlacement> p;
    const Vec3d far{1e4, -1e4 / 3, 77.7};
    for (double scale : {1e-3, 1.0, 1e3})
        for (const Vec3d& offset : {Vec3d{0, 0, 0}, far})
            p.push_back({"axis-aligned scale " + std::to_string(scale) + (offset.x != 0 ? " offset 1e4" : ""),
                         {Vec3d{scale, 0, 0}, Vec3d{0, scale, 0}, Vec3d{0, 0, scale}}, offset});
    const std::array<Vec3d, 3> exact_rotation = cad_rotation(26);
    for (int e : {-10, 0, 10})
        for (const Vec3d& offset : {Vec3d{0, 0, 0}, Vec3d{10000.375, -2500.5, 1234.25}}) {
            CadPlacement q{"exact rotation scale 2^" + std::to_string(e) + (offset.x != 0 ? " offset 1e4" : ""), exact_rotation,
                           offset};
            for (Vec3d& a : q.axes) a = a * std::ldexp(1.0, e);
            p.push_back(q);
        }
    for (double scale : {1e-3, 1e3}) {
        CadPlacement q{"rounded rotation scale " + std::to_string(scale) + " offset 1e4", cad_rotation(0), far};
        for (Vec3d& a : q.axes) a = a * scale;
        p.push_back(q);
    }
    return p;
}

namespace cad_detail {

using GridPoint = std::array<int, 3>;

/// Builds the mesh panel by panel; vertices are keyed by their grid point, so that panels
/// sharing an edge share its points.
class CadBuilder {
public:
    CadBuilder(const CadSolid& solid, const CadPlacement& place) : solid_(solid), place_(place) {}

    TriangleMesh build() {
        mesh_.name = "cad_" + solid_.name;
        mesh_.source = "cad:" + solid_.name + " (" + place_.label + ")";
        const int n[3] = {int(solid_.lines[0].size()) - 1, int(solid_.lines[1].size()) - 1, int(solid_.lines[2].size()) - 1};
        for (const auto& c : solid_.cells)
            for (int axis = 0; axis < 3; ++axis)
                for (int side : {-1, 1}) {
                    GridPoint nb = c;
                    nb[size_t(axis)] += side;
                    const bool inside_grid = nb[size_t(axis)] >= 0 && nb[size_t(axis)] < n[axis];
                    if (!inside_grid || !solid_.occupied(nb[0], nb[1], nb[2])) add_panel(c, axis, side);
                }
        return mesh_;
    }

private:
    int vertex(const GridPoint& g) {
        auto [it, fresh] = ids_.try_emplace(g, int(mesh_.vertices.size()));
        if (fresh) mesh_.vertices.push_back(place_.apply(Vec3d{double(g[0]), double(g[1]), double(g[2])}));
        return it->second;
    }

    /// How many parts the edge a-b is split into (the same from both panels): 1 half the time.
    static int parts(GridPoint a, GridPoint b) {
        if (b < a) std::swap(a, b);
        static const int table[6] = {1, 1, 1, 2, 3, 4};
        const int h = a[0] * 7 + a[1] * 11 + a[2] * 13 + b[0] * 17 + b[1] * 19 + b[2] * 23;
        return h % 97 == 0 ? 6 : table[h % 6];
    }

    /// The points from a (included) to b (excluded) along the edge.
    std::vector<int> edge_points(const GridPoint& a, const GridPoint& b) {
        const int k = parts(a, b);
        std::vector<int> out;
        for (int j = 0; j < k; ++j) {
            GridPoint g;
            for (int d = 0; d < 3; ++d) g[size_t(d)] = a[size_t(d)] + (b[size_t(d)] - a[size_t(d)]) * j / k;
            out.push_back(vertex(g));
        }
        return out;
    }

    void add_panel(const GridPoint& cell, int axis, int side) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        const int w = solid_.lines[size_t(axis)][size_t(cell[size_t(axis)] + (side > 0 ? 1 : 0))];
        const int u0 = solid_.lines[size_t(u)][size_t(cell[size_t(u)])], u1 = solid_.lines[size_t(u)][size_t(cell[size_t(u)] + 1)];
        const int v0 = solid_.lines[size_t(v)][size_t(cell[size_t(v)])], v1 = solid_.lines[size_t(v)][size_t(cell[size_t(v)] + 1)];
        auto at = [&](int pu, int pv) {
            GridPoint g;
            g[size_t(axis)] = w;
            g[size_t(u)] = pu;
            g[size_t(v)] = pv;
            return g;
        };
        // Counter-clockwise seen from outside: e_u x e_v = e_axis.
        std::array<GridPoint, 4> corner = {at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1)};
        if (side < 0) std::swap(corner[1], corner[3]);
        std::array<std::vector<int>, 4> edge;  // edge s: corner s (included) .. corner s+1 (excluded)
        std::array<int, 4> count;
        for (int s = 0; s < 4; ++s) {
            edge[size_t(s)] = edge_points(corner[size_t(s)], corner[size_t((s + 1) % 4)]);
            count[size_t(s)] = int(edge[size_t(s)].size());
        }
        const int style = panels_++ % 3;
        if (style == 0 && strip(edge, count)) return;
        if (style <= 1 && corner_fan(edge, count)) return;
        centre_fan(edge, at((u0 + u1) / 2, (v0 + v1) / 2));
    }

    /// Zigzag between two opposite edges when the other two are unsplit.
    bool strip(const std::array<std::vector<int>, 4>& edge, const std::array<int, 4>& count) {
        for (int s = 0; s < 2; ++s) {
            if (count[size_t(s + 1)] != 1 || count[size_t((s + 3) % 4)] != 1) continue;
            std::vector<int> bottom = edge[size_t(s)], top = edge[size_t(s + 2)];
            bottom.push_back(edge[size_t(s + 1)][0]);       // ends at corner s+1
            top.push_back(edge[size_t((s + 3) % 4)][0]);    // ends at corner s+3
            std::reverse(top.begin(), top.end());           // from corner s+3 to corner s+2
            const size_t nb = bottom.size() - 1, nt = top.size() - 1;
            size_t i = 0, j = 0;
            while (i < nb || j < nt) {
                if (j == nt || (i < nb && (i + 1) * nt <= (j + 1) * nb)) {
                    add(bottom[i], bottom[i + 1], top[j]);
                    ++i;
                } else {
                    add(bottom[i], top[j + 1], top[j]);
                    ++j;
                }
            }
            return true;
        }
        return false;
    }

    /// A fan from a corner whose two edges are unsplit, over the points of the other two.
    bool corner_fan(const std::array<std::vector<int>, 4>& edge, const std::array<int, 4>& count) {
        for (int s = 0; s < 4; ++s) {
            if (count[size_t(s)] != 1 || count[size_t((s + 3) % 4)] != 1) continue;
            const int apex = edge[size_t(s)][0];
            std::vector<int> far = edge[size_t((s + 1) % 4)];
            far.insert(far.end(), edge[size_t((s + 2) % 4)].begin(), edge[size_t((s + 2) % 4)].end());
            far.push_back(edge[size_t((s + 3) % 4)][0]);
            for (size_t k = 0; k + 1 < far.size(); ++k) add(apex, far[k], far[k + 1]);
            return true;
        }
        return false;
    }

    void centre_fan(const std::array<std::vector<int>, 4>& edge, const GridPoint& centre) {
        std::vector<int> ring;
        for (const auto& e : edge) ring.insert(ring.end(), e.begin(), e.end());
        const int c = vertex(centre);
        for (size_t k = 0; k < ring.size(); ++k) add(c, ring[k], ring[(k + 1) % ring.size()]);
    }

    void add(int a, int b, int c) { mesh_.triangles.push_back({a, b, c}); }

    const CadSolid& solid_;
    const CadPlacement& place_;
    TriangleMesh mesh_;
    std::map<GridPoint, int> ids_;
    int panels_ = 0;
};

}  // namespace cad_detail

/// The solid's surface as a CAD exporter would triangulate it, placed in the world.
inline TriangleMesh cad_mesh(const CadSolid& solid, const CadPlacement& place) {
    return cad_detail::CadBuilder(solid, place).build();
}

/// Grid points (cell centres) inside and outside the solid, for checking signs: centres of
/// occupied cells, of empty cells, and of the cells around the grid.
inline void cad_cell_centres(const CadSolid& solid, std::vector<Vec3d>& inside, std::vector<Vec3d>& outside) {
    const auto& L = solid.lines;
    auto centre = [&](int a, int i) {
        const std::vector<int>& l = L[size_t(a)];
        if (i < 0) return l.front() - 6.0;
        if (i >= int(l.size()) - 1) return l.back() + 6.0;
        return 0.5 * (l[size_t(i)] + l[size_t(i + 1)]);
    };
    for (int i = -1; i < int(L[0].size()); ++i)
        for (int j = -1; j < int(L[1].size()); ++j)
            for (int k = -1; k < int(L[2].size()); ++k) {
                const Vec3d g{centre(0, i), centre(1, j), centre(2, k)};
                (solid.occupied(i, j, k) ? inside : outside).push_back(g);
            }
}

}  // namespace sdf::test
