#include "core/mesh/polygon_triangulation.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>
#include <utility>

#include "core/parallel/task_monitor.h"

namespace sdf {
namespace {

/// Twice the polygon's vector area (Newell's method), of corners taken relative to the
/// first one, so that far-away coordinates do not cancel.
Vec3d newell_normal(const std::vector<Vec3d>& p) {
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
double non_planarity(const std::vector<Vec3d>& p, const Vec3d& normal) {
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

/// The corners that are not strictly convex, bucketed on a uniform grid of the projection
/// plane, so that an ear test looks only at those in its triangle's box: O(1) corners per
/// test for polygons whose corners are spread evenly, instead of all of them. A test whose
/// box covers more cells than there are such corners walks their list instead, so no test
/// costs more than the plain scan.
class ReflexGrid {
public:
    ReflexGrid(const std::vector<Vec3d>& p, const Projection& proj) : u_(proj.u), v_(proj.v), cell_of_(p.size(), -1) {
        double lo[2] = {p[0][u_], p[0][v_]}, hi[2] = {lo[0], lo[1]};
        for (const Vec3d& q : p) {
            lo[0] = std::min(lo[0], q[u_]); hi[0] = std::max(hi[0], q[u_]);
            lo[1] = std::min(lo[1], q[v_]); hi[1] = std::max(hi[1], q[v_]);
        }
        // About one cell per corner, square where the box allows.
        const double w = hi[0] - lo[0], h = hi[1] - lo[1], n = double(p.size());
        const double aspect = w > 0 && h > 0 && std::isfinite(w / h) ? std::clamp(w / h, 1.0 / n, n) : 1.0;
        cells_[0] = w > 0 ? int(std::clamp(std::sqrt(n * aspect), 1.0, n)) : 1;
        cells_[1] = h > 0 ? int(std::clamp(n / cells_[0], 1.0, n)) : 1;
        for (int k = 0; k < 2; ++k) {
            origin_[k] = lo[k];
            const double extent = hi[k] - lo[k];
            scale_[k] = extent > 0 ? double(cells_[k]) / extent : 0.0;
        }
        head_.assign(size_t(cells_[0]) * size_t(cells_[1]), -1);
        next_.assign(p.size(), -1);
        prev_.assign(p.size(), -1);
        position_.assign(p.size(), -1);
    }

    bool contains(int i) const { return cell_of_[size_t(i)] >= 0; }

    void insert(int i, const Vec3d& q) {
        if (contains(i)) return;
        const int c = cell(q[u_], 0) + cells_[0] * cell(q[v_], 1);
        cell_of_[size_t(i)] = c;
        prev_[size_t(i)] = -1;
        next_[size_t(i)] = head_[size_t(c)];
        if (next_[size_t(i)] >= 0) prev_[size_t(next_[size_t(i)])] = i;
        head_[size_t(c)] = i;
        position_[size_t(i)] = int(all_.size());
        all_.push_back(i);
    }

    void erase(int i) {
        if (!contains(i)) return;
        const int c = cell_of_[size_t(i)];
        if (prev_[size_t(i)] >= 0) next_[size_t(prev_[size_t(i)])] = next_[size_t(i)];
        else head_[size_t(c)] = next_[size_t(i)];
        if (next_[size_t(i)] >= 0) prev_[size_t(next_[size_t(i)])] = prev_[size_t(i)];
        cell_of_[size_t(i)] = -1;
        const int last = all_.back();
        all_[size_t(position_[size_t(i)])] = last;
        position_[size_t(last)] = position_[size_t(i)];
        all_.pop_back();
        position_[size_t(i)] = -1;
    }

    /// Calls stop(j) for the corners whose position may lie in the box of a, b, c (every
    /// corner that does, perhaps others); returns the first j for which stop(j) is true, or -1.
    template <typename Stop>
    int find(const Vec3d& a, const Vec3d& b, const Vec3d& c, Stop stop) const {
        const int x0 = cell(std::min({a[u_], b[u_], c[u_]}), 0), x1 = cell(std::max({a[u_], b[u_], c[u_]}), 0);
        const int y0 = cell(std::min({a[v_], b[v_], c[v_]}), 1), y1 = cell(std::max({a[v_], b[v_], c[v_]}), 1);
        if (double(x1 - x0 + 1) * double(y1 - y0 + 1) > double(all_.size())) {
            for (const int j : all_)
                if (stop(j)) return j;
            return -1;
        }
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                for (int j = head_[size_t(x + cells_[0] * y)]; j >= 0; j = next_[size_t(j)])
                    if (stop(j)) return j;
        return -1;
    }

private:
    /// The cell column (k = 0) or row (k = 1) of a coordinate: non-decreasing in it, so the
    /// cells of a box's corners bound the cells of every point inside it.
    int cell(double x, int k) const {
        const double t = (x - origin_[k]) * scale_[k];
        if (!(t > 0)) return 0;  // NaN (0 * infinity) too
        return t >= double(cells_[k]) ? cells_[k] - 1 : int(t);
    }

    int u_, v_;
    int cells_[2] = {1, 1};
    double origin_[2] = {0, 0}, scale_[2] = {0, 0};
    std::vector<int> head_;            ///< first corner of each cell, -1 if none
    std::vector<int> next_, prev_;     ///< the cell's list
    std::vector<int> cell_of_;         ///< each corner's cell, -1 when not in the grid
    std::vector<int> all_, position_;  ///< every corner in the grid, and each one's place there
};

/// Ear clipping of one polygon (corners without consecutive repeats), as described in the header.
///
/// What a test depends on is kept track of, so that no test is repeated in vain: a corner's
/// ear test depends on its two neighbours (it is tested again when one of them is clipped)
/// and on the set S of live corners that are not strictly convex (ReflexGrid). A corner
/// that is no ear because of a corner j of S stays none until j leaves S (is clipped or turns
/// convex: then the corner waits in `recheck_`); one that is no ear by its own shape stays
/// none until a neighbour changes. So when no ear is known (`ears_` empty), retesting only
/// `recheck_` finds exactly the ears that testing every corner would find, and the clipping
/// order, hence every triangle, is that of the plain algorithm, in O(n log n) for polygons
/// whose corners are spread evenly (one 40,000-corner polygon: milliseconds, not 30 s).
class EarClipper {
public:
    EarClipper(const std::vector<Vec3d>& p, const std::vector<int>& ids, Projection proj, std::vector<Int3>& out)
        : p_(p), ids_(ids), proj_(proj), out_(out), prev_(p.size()), next_(p.size()), alive_(p.size(), true),
          key_(p.size(), -1.0), blocked_(p.size()), reflex_(p, proj), monitor_(current_task_monitor()) {
        const int n = int(p.size());
        for (int i = 0; i < n; ++i) { prev_[size_t(i)] = (i + n - 1) % n; next_[size_t(i)] = (i + 1) % n; }
        for (int i = 0; i < n; ++i)
            if (!convex(i)) reflex_.insert(i, p_[size_t(i)]);
        left_ = n;
    }

    /// Clips every ear; returns false when the polygon ran out of ears (not simple).
    bool run() {
        bool simple = true;
        for (int i = 0; i < int(p_.size()); ++i) update(i);
        while (left_ > 3) {
            // Every 4096 clips: a polygon of millions of corners stops on request (Ctrl-C in Python).
            if (monitor_ && (left_ & 4095) == 0 && monitor_->stop_requested()) throw TaskStopped();
            if (ears_.empty()) recheck();  // a removed corner may have unblocked an ear elsewhere
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
    static constexpr int kEar = -1, kOwnShape = -2;

    void clip(int tip) {
        const int a = prev_[size_t(tip)], c = next_[size_t(tip)];
        emit(a, tip, c);
        forget(tip);
        alive_[size_t(tip)] = false;
        leave_reflex(tip);
        next_[size_t(a)] = c;
        prev_[size_t(c)] = a;
        --left_;
        for (const int corner : {a, c}) {
            // In a polygon that is not simple, a corner may turn either way.
            if (!convex(corner)) reflex_.insert(corner, p_[size_t(corner)]);
            else leave_reflex(corner);
        }
        update(a);
        update(c);
    }

    /// `j` leaves S: the corners it blocked are tested again when ears run out.
    void leave_reflex(int j) {
        if (!reflex_.contains(j)) return;
        reflex_.erase(j);
        std::vector<int>& blocked = blocked_[size_t(j)];
        recheck_.insert(recheck_.end(), blocked.begin(), blocked.end());
        blocked.clear();
        blocked.shrink_to_fit();
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

    /// kEar, kOwnShape (not strictly convex, or a triangle prepare_mesh() drops), or the
    /// corner of S that lies in its triangle.
    int ear_test(int i) const {
        const int a = prev_[size_t(i)], c = next_[size_t(i)];
        const Vec3d &pa = p_[size_t(a)], &pi = p_[size_t(i)], &pc = p_[size_t(c)];
        if (!convex(i)) return kOwnShape;
        // prepare_mesh() drops a triangle whose cross product is exactly 0 in double (from
        // whichever corner comes first); a "convex" corner whose triangle it would drop (a
        // rounding artefact of near-collinear corners) is no ear either.
        if (length_squared(cross(pi - pa, pc - pa)) == 0.0 || length_squared(cross(pc - pi, pa - pi)) == 0.0 ||
            length_squared(cross(pa - pc, pi - pc)) == 0.0)
            return kOwnShape;
        // Only corners that are not strictly convex need a look: a triangle that holds a
        // corner of a simple polygon holds a reflex (or collinear) one (Eberly 2002).
        const int blocker = reflex_.find(pa, pi, pc, [&](int j) {
            if (j == a || j == i || j == c) return false;
            const Vec3d& q = p_[size_t(j)];
            if (q == pa || q == pi || q == pc) return false;  // a corner visited twice (a keyhole) blocks nothing
            return proj_.orient(pa, pi, q) >= 0 && proj_.orient(pi, pc, q) >= 0 && proj_.orient(pc, pa, q) >= 0;
        });
        return blocker >= 0 ? blocker : kEar;
    }

    void forget(int i) {
        if (key_[size_t(i)] >= 0) ears_.erase({key_[size_t(i)], rank(i)});
        key_[size_t(i)] = -1.0;
    }

    void update(int i) {
        forget(i);
        const int test = ear_test(i);
        if (test >= 0) blocked_[size_t(test)].push_back(i);
        if (test != kEar) return;
        key_[size_t(i)] = length_squared(p_[size_t(next_[size_t(i)])] - p_[size_t(prev_[size_t(i)])]);
        ears_.insert({key_[size_t(i)], rank(i)});
    }

    /// Order among ears with equal cuts: the face's first corner last, so that a rectangle
    /// or a regular polygon becomes the fan from its first corner.
    int rank(int i) const { return i == 0 ? int(p_.size()) : i; }

    /// The corners whose blocker left S since their test (the only ones that may have become ears).
    void recheck() {
        std::vector<int> corners;
        corners.swap(recheck_);
        for (const int i : corners)
            if (alive_[size_t(i)] && key_[size_t(i)] < 0) update(i);
    }

    /// The corner that turns the polygon's way the most, the first of equals (a fallback:
    /// it may hold other corners).
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
    std::vector<double> key_;                 ///< squared cut length of each corner that is an ear, else -1
    std::set<std::pair<double, int>> ears_;  ///< (squared cut length, rank): shortest cut first
    std::vector<std::vector<int>> blocked_;   ///< the corners each corner of S blocked when last tested
    std::vector<int> recheck_;                ///< corners whose blocker left S
    ReflexGrid reflex_;                       ///< S: live corners not strictly convex
    TaskMonitor* monitor_;
    int left_ = 0;
};

}  // namespace

void triangulate_polygon(const std::vector<Vec3d>& vertices, const std::vector<int>& corners, std::vector<Int3>& out,
                         PolygonStats& stats) {
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

void PolygonList::triangulate_into(TriangleMesh& mesh) const {
    std::vector<int> face;
    size_t at = 0;
    for (const int n : sizes) {
        face.assign(corners.begin() + std::ptrdiff_t(at), corners.begin() + std::ptrdiff_t(at + size_t(n)));
        at += size_t(n);
        triangulate_polygon(mesh.vertices, face, mesh.triangles, mesh.polygon_stats);
    }
}

}  // namespace sdf
