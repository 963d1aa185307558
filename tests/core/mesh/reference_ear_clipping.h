/// @file reference_ear_clipping.h
/// @brief The ear clipping of polygon_triangulation.cpp as it was before issue 38: every ear
/// test scans every corner that is not convex, and every corner is tested again whenever no
/// ear is known (O(n r), quadratic). Kept for the tests only, as the reference that the
/// faster clipper's triangles must equal triangle for triangle.
#pragma once

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "core/bounds3.h"
#include "core/mesh/polygon_triangulation.h"
#include "core/mesh/triangle_mesh.h"

namespace sdf::reference {

/// Twice the polygon's vector area (Newell's method), of corners taken relative to the
/// first one, so that far-away coordinates do not cancel.
inline Vec3d newell_normal(const std::vector<Vec3d>& p) {
    Vec3d n(0.0);
    for (size_t i = 0; i < p.size(); ++i) {
        const Vec3d a = p[i] - p[0], b = p[(i + 1) % p.size()] - p[0];
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    return n;
}

/// Largest distance of a corner from the plane through the corners' centroid normal to
/// `normal`, over the polygon's bounding-box diagonal.
inline double non_planarity(const std::vector<Vec3d>& p, const Vec3d& normal) {
    const double n = length(normal);
    if (n == 0) return 0;
    const Vec3d unit = normal / n;
    Vec3d centroid(0.0);
    Bounds3 box;
    for (const Vec3d& q : p) { centroid += (q - p[0]) / double(p.size()); box.extend(q); }
    double deviation = 0;
    for (const Vec3d& q : p) deviation = std::max(deviation, std::abs(dot(q - p[0] - centroid, unit)));
    const double size = box.diagonal();
    return size > 0 ? deviation / size : 0;
}

/// The coordinate plane the polygon is clipped in: the axes (u, v) cyclically after the
/// normal's largest component, and the sign that keeps the polygon counter-clockwise.
struct Projection {
    int u = 0, v = 1;
    double sign = 1;

    explicit Projection(const Vec3d& normal) {
        const Vec3d a{std::abs(normal.x), std::abs(normal.y), std::abs(normal.z)};
        const int axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
        u = (axis + 1) % 3;
        v = (axis + 2) % 3;
        sign = normal[axis] < 0 ? -1.0 : 1.0;
    }
    /// > 0 where a, b, c turn the polygon's way (counter-clockwise in the projection).
    double orient(const Vec3d& a, const Vec3d& b, const Vec3d& c) const {
        return sign * ((b[u] - a[u]) * (c[v] - a[v]) - (b[v] - a[v]) * (c[u] - a[u]));
    }
};

/// Ear clipping of one polygon (corners without consecutive repeats), as described in the header.
class EarClipper {
public:
    EarClipper(const std::vector<Vec3d>& p, const std::vector<int>& ids, Projection proj, std::vector<Int3>& out)
        : p_(p), ids_(ids), proj_(proj), out_(out), prev_(p.size()), next_(p.size()), alive_(p.size(), true),
          key_(p.size(), -1.0) {
        const int n = int(p.size());
        for (int i = 0; i < n; ++i) { prev_[size_t(i)] = (i + n - 1) % n; next_[size_t(i)] = (i + 1) % n; }
        for (int i = 0; i < n; ++i)
            if (!convex(i)) reflex_.push_back(i);
        left_ = n;
    }

    /// Clips every ear; returns false when the polygon ran out of ears (not simple).
    bool run() {
        bool simple = true;
        update_all();
        while (left_ > 3) {
            if (ears_.empty()) update_all();  // a removed corner may have unblocked an ear elsewhere
            int tip = -1;
            if (!ears_.empty()) {
                tip = ears_.begin()->second % int(p_.size());
            } else {
                simple = false;
                tip = most_convex();
            }
            clip(tip);
        }
        int a = 0;
        while (!alive_[size_t(a)]) ++a;
        emit(a, next_[size_t(a)], next_[size_t(next_[size_t(a)])]);
        return simple;
    }

private:
    void clip(int tip) {
        const int a = prev_[size_t(tip)], c = next_[size_t(tip)];
        emit(a, tip, c);
        forget(tip);
        alive_[size_t(tip)] = false;
        next_[size_t(a)] = c;
        prev_[size_t(c)] = a;
        --left_;
        for (const int corner : {a, c})
            if (!convex(corner)) reflex_.push_back(corner);  // in a polygon that is not simple, a corner may turn
        update(a);
        update(c);
    }

    /// Strictly convex: turns the polygon's way (a collinear corner does not).
    bool convex(int i) const {
        return proj_.orient(p_[size_t(prev_[size_t(i)])], p_[size_t(i)], p_[size_t(next_[size_t(i)])]) > 0;
    }

    /// The triangle (a, b, c), turned to start at the corner that comes first in the face.
    void emit(int a, int b, int c) {
        if (b < a && b < c) std::tie(a, b, c) = std::make_tuple(b, c, a);
        else if (c < a && c < b) std::tie(a, b, c) = std::make_tuple(c, a, b);
        out_.push_back({ids_[size_t(a)], ids_[size_t(b)], ids_[size_t(c)]});
    }

    bool is_ear(int i) const {
        const int a = prev_[size_t(i)], c = next_[size_t(i)];
        const Vec3d &pa = p_[size_t(a)], &pi = p_[size_t(i)], &pc = p_[size_t(c)];
        if (!convex(i)) return false;
        // prepare_mesh() drops a triangle whose cross product is exactly 0 in double (from
        // whichever corner comes first); a "convex" corner whose triangle it would drop (a
        // rounding artefact of near-collinear corners) is no ear either.
        if (length_squared(cross(pi - pa, pc - pa)) == 0.0 || length_squared(cross(pc - pi, pa - pi)) == 0.0 ||
            length_squared(cross(pa - pc, pi - pc)) == 0.0)
            return false;
        // Only corners that are not strictly convex need a look: a triangle that holds a
        // corner of a simple polygon holds a reflex (or collinear) one (Eberly 2002).
        for (const int j : reflex_) {
            if (!alive_[size_t(j)] || j == a || j == i || j == c || convex(j)) continue;
            const Vec3d& q = p_[size_t(j)];
            if (q == pa || q == pi || q == pc) continue;  // a corner visited twice (a keyhole) blocks nothing
            if (proj_.orient(pa, pi, q) >= 0 && proj_.orient(pi, pc, q) >= 0 && proj_.orient(pc, pa, q) >= 0) return false;
        }
        return true;
    }

    void forget(int i) {
        if (key_[size_t(i)] >= 0) ears_.erase({key_[size_t(i)], rank(i)});
        key_[size_t(i)] = -1.0;
    }

    void update(int i) {
        forget(i);
        if (!is_ear(i)) return;
        key_[size_t(i)] = length_squared(p_[size_t(next_[size_t(i)])] - p_[size_t(prev_[size_t(i)])]);
        ears_.insert({key_[size_t(i)], rank(i)});
    }

    /// Order among ears with equal cuts: the face's first corner last, so that a rectangle
    /// or a regular polygon becomes the fan from its first corner.
    int rank(int i) const { return i == 0 ? int(p_.size()) : i; }

    void update_all() {
        for (int i = 0; i < int(p_.size()); ++i)
            if (alive_[size_t(i)]) update(i);
    }

    /// The corner that turns the polygon's way the most (a fallback: it may hold other corners).
    int most_convex() const {
        int best = -1;
        double best_turn = 0;
        for (int i = 0; i < int(p_.size()); ++i) {
            if (!alive_[size_t(i)]) continue;
            const double turn = proj_.orient(p_[size_t(prev_[size_t(i)])], p_[size_t(i)], p_[size_t(next_[size_t(i)])]);
            if (best < 0 || turn > best_turn) { best = i; best_turn = turn; }
        }
        return best;
    }

    const std::vector<Vec3d>& p_;
    const std::vector<int>& ids_;
    Projection proj_;
    std::vector<Int3>& out_;
    std::vector<int> prev_, next_;
    std::vector<bool> alive_;
    std::vector<int> reflex_;              ///< corners not strictly convex when last seen (some may be by now)
    std::vector<double> key_;              ///< squared cut length of each corner that is an ear, else -1
    std::set<std::pair<double, int>> ears_;  ///< (squared cut length, rank): shortest cut first
    int left_ = 0;
};


/// triangulate_polygon() as it was (the same rules, the quadratic clipper).
inline void triangulate_polygon(const std::vector<Vec3d>& vertices, const std::vector<int>& corners,
                                std::vector<Int3>& out, PolygonStats& stats) {
    if (corners.size() == 3) { out.push_back({corners[0], corners[1], corners[2]}); return; }
    ++stats.polygons;
    // Rule 1: no corner at the position of the corner before it.
    std::vector<int> ids;
    std::vector<Vec3d> p;
    for (size_t i = 0; i < corners.size(); ++i) {
        const Vec3d& q = vertices[size_t(corners[i])];
        if (!p.empty() && q == p.back()) continue;
        ids.push_back(corners[i]);
        p.push_back(q);
    }
    while (p.size() > 1 && p.back() == p.front()) { p.pop_back(); ids.pop_back(); }
    if (p.size() < 3) {
        // No area at all: a fan of the face as written, whose triangles prepare_mesh() drops and counts.
        ++stats.not_simple;
        for (size_t j = 1; j + 1 < corners.size(); ++j) out.push_back({corners[0], corners[j], corners[j + 1]});
        return;
    }
    if (p.size() == 3) { out.push_back({ids[0], ids[1], ids[2]}); return; }

    const Vec3d normal = newell_normal(p);
    const double deviation = non_planarity(p, normal);
    stats.max_non_planarity = std::max(stats.max_non_planarity, deviation);
    if (deviation > kNonPlanarTolerance) ++stats.non_planar;
    if (!EarClipper(p, ids, Projection(normal), out).run() || length_squared(normal) == 0) ++stats.not_simple;
}
}  // namespace sdf::reference
