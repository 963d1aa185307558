#include "core/mesh/polygon_triangulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

/// The three edges of an ear's triangle, each as the half-plane orient(e0, e1, q) >= 0 that
/// the ear test asks, as the projection computes it.
struct CornerEdges {
    struct Edge {
        double au, av, du, dv, sign, magnitude;
    } edge[3];
};

/// A k-d tree of tight boxes over a fixed list of corners (in the projection's plane), each
/// node counting the corners below it that are in the set S of the ear test, so that a
/// search skips boxes without one. An ear test visits only the boxes its triangle may reach:
/// a box is skipped when one of the triangle's edges has every corner of the box outside it
/// by more than that edge's rounding error, so every corner the plain scan's computed test
/// could accept is still tested (the same answers).
class CornerTree {
public:
    /// Over `corners`, every one of them in S.
    CornerTree(const std::vector<Vec3d>& p, const Projection& proj, std::vector<int> corners)
        : p_(p), proj_(proj), items_(std::move(corners)), leaf_of_(items_.size(), -1) {
        if (!items_.empty()) build(0, int(items_.size()), -1);
    }

    size_t size() const { return items_.size(); }
    /// The corners, each at its slot.
    const std::vector<int>& corners() const { return items_; }
    /// The corner at `slot` joins (+1) or leaves (-1) S.
    void count(int slot, int change) {
        for (int n = leaf_of_[size_t(slot)]; n >= 0; n = nodes_[size_t(n)].parent) nodes_[size_t(n)].alive += change;
    }

    /// The first corner j of S (in no particular order) that the triangle with `edges` may
    /// hold and for which stop(j) is true, or -1.
    template <typename InS, typename Stop>
    int find(const CornerEdges& edges, InS in_s, Stop stop) const {
        if (nodes_.empty() || nodes_[0].alive == 0) return -1;
        int stack[64 * 2];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& n = nodes_[size_t(stack[--top])];
            if (n.alive == 0 || outside(n, edges)) continue;
            if (n.child[0] < 0) {
                for (int s = n.begin; s < n.end; ++s) {
                    const int j = items_[size_t(s)];
                    if (in_s(j) && stop(j)) return j;
                }
                continue;
            }
            stack[top++] = n.child[0];
            stack[top++] = n.child[1];
        }
        return -1;
    }

private:
    struct Node {
        double lo[2], hi[2];  ///< the tight box of its corners, in the projection's (u, v)
        int begin, end;       ///< its corners: items_[begin, end)
        int child[2] = {-1, -1};
        int parent;
        int alive;            ///< corners of S among them
    };

    double u(const Vec3d& q) const { return q[proj_.u]; }
    double v(const Vec3d& q) const { return q[proj_.v]; }

    /// True when every point of the box is outside one of the edges by more than the
    /// rounding of the ear test's orient() (a few units of 2^-52 of the products: 16 used).
    static bool outside(const Node& n, const CornerEdges& edges) {
        constexpr double kRounding = 16 * std::numeric_limits<double>::epsilon();
        for (const CornerEdges::Edge& e : edges.edge) {
            double most = -std::numeric_limits<double>::infinity(), reach = 0;
            for (int k = 0; k < 4; ++k) {
                const double qu = (k & 1 ? n.hi[0] : n.lo[0]) - e.au, qv = (k & 2 ? n.hi[1] : n.lo[1]) - e.av;
                most = std::max(most, e.sign * (e.du * qv - e.dv * qu));
                reach = std::max(reach, std::abs(qu) + std::abs(qv));
            }
            if (most < -2 * kRounding * e.magnitude * reach) return true;
        }
        return false;
    }

    int build(int begin, int end, int parent) {
        const int index = int(nodes_.size());
        nodes_.push_back(Node{});
        Node n;
        n.begin = begin;
        n.end = end;
        n.parent = parent;
        n.alive = end - begin;
        n.lo[0] = n.lo[1] = std::numeric_limits<double>::infinity();
        n.hi[0] = n.hi[1] = -std::numeric_limits<double>::infinity();
        for (int s = begin; s < end; ++s) {
            const Vec3d& q = p_[size_t(items_[size_t(s)])];
            n.lo[0] = std::min(n.lo[0], u(q)); n.hi[0] = std::max(n.hi[0], u(q));
            n.lo[1] = std::min(n.lo[1], v(q)); n.hi[1] = std::max(n.hi[1], v(q));
        }
        if (end - begin <= kLeafSize) {
            for (int s = begin; s < end; ++s) leaf_of_[size_t(s)] = index;
        } else {
            // Halves along the longer side (the median): a depth of log2(n / kLeafSize).
            const int axis = n.hi[0] - n.lo[0] >= n.hi[1] - n.lo[1] ? proj_.u : proj_.v;
            const int mid = begin + (end - begin) / 2;
            std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end,
                             [&](int x, int y) { return p_[size_t(x)][axis] < p_[size_t(y)][axis]; });
            n.child[0] = build(begin, mid, index);
            n.child[1] = build(mid, end, index);
        }
        nodes_[size_t(index)] = n;
        return index;
    }

    static constexpr int kLeafSize = 8;
    const std::vector<Vec3d>& p_;
    Projection proj_;
    std::vector<int> items_;    ///< the corners, each node's a range
    std::vector<int> leaf_of_;  ///< the leaf of each slot of items_
    std::vector<Node> nodes_;
};

/// The set S of the ear test: the live corners that are not strictly convex. Those of the
/// start sit in one CornerTree. A corner joins S later only in a polygon that crosses itself
/// (in a simple one, clipping an ear makes its neighbours more convex, never less); such
/// corners go to trees of their own, kept as Bentley and Saxe's logarithmic method keeps a
/// static structure dynamic: a new corner and every tree no larger than what it gathered are
/// rebuilt as one (the trees' sizes halve from one to the next, so a search visits O(log n)
/// trees and each corner is rebuilt O(log n) times). A list of late corners scanned by every
/// ear test made such polygons quadratic.
class ReflexCorners {
public:
    ReflexCorners(const std::vector<Vec3d>& p, const Projection& proj, std::vector<int> initial)
        : p_(p), proj_(proj), member_(p.size(), 0), tree_of_(p.size(), -1), slot_(p.size(), -1) {
        for (const int i : initial) member_[size_t(i)] = 1;
        add_tree(std::move(initial));
    }

    bool contains(int i) const { return member_[size_t(i)] != 0; }

    void insert(int i) {
        if (contains(i)) return;
        member_[size_t(i)] = 1;
        if (tree_of_[size_t(i)] >= 0) return trees_[size_t(tree_of_[size_t(i)])].count(slot_[size_t(i)], +1);
        // Gather the late trees no larger than what is gathered (their corners still in S).
        std::vector<int> corners = {i};
        while (trees_.size() > 1 && trees_.back().size() <= corners.size()) {
            for (const int j : trees_.back().corners()) {
                tree_of_[size_t(j)] = -1;
                if (contains(j)) corners.push_back(j);
            }
            trees_.pop_back();
        }
        add_tree(std::move(corners));
    }

    void erase(int i) {
        if (!contains(i)) return;
        member_[size_t(i)] = 0;
        trees_[size_t(tree_of_[size_t(i)])].count(slot_[size_t(i)], -1);
    }

    /// The first corner j of S (in no particular order) that the triangle (a, b, c) may hold
    /// and for which stop(j) is true, or -1; every corner of S that it may hold is offered.
    template <typename Stop>
    int find(const Vec3d& a, const Vec3d& b, const Vec3d& c, Stop stop) const {
        const Vec3d* corners[3] = {&a, &b, &c};
        CornerEdges edges;
        for (int k = 0; k < 3; ++k) {
            const Vec3d &e0 = *corners[k], &e1 = *corners[(k + 1) % 3];
            const double du = e1[proj_.u] - e0[proj_.u], dv = e1[proj_.v] - e0[proj_.v];
            edges.edge[k] = {e0[proj_.u], e0[proj_.v], du, dv, proj_.sign, std::abs(du) + std::abs(dv)};
        }
        const auto in_s = [&](int j) { return contains(j); };
        for (const CornerTree& tree : trees_) {
            const int j = tree.find(edges, in_s, stop);
            if (j >= 0) return j;
        }
        return -1;
    }

private:
    void add_tree(std::vector<int> corners) {
        trees_.emplace_back(p_, proj_, std::move(corners));
        const std::vector<int>& placed = trees_.back().corners();
        for (size_t s = 0; s < placed.size(); ++s) {
            tree_of_[size_t(placed[s])] = int(trees_.size()) - 1;
            slot_[size_t(placed[s])] = int(s);
        }
    }

    const std::vector<Vec3d>& p_;
    Projection proj_;
    std::vector<char> member_;       ///< in S
    std::vector<int> tree_of_;       ///< the tree holding each corner, -1 for none
    std::vector<int> slot_;          ///< its slot there
    std::vector<CornerTree> trees_;  ///< the start's corners, then late ones in trees of decreasing size
};

/// Ear clipping of one polygon (corners without consecutive repeats), as described in the header.
///
/// What a test depends on is kept track of, so that no test is repeated in vain: a corner's
/// ear test depends on its two neighbours (it is tested again when one of them is clipped)
/// and on the set S of live corners that are not strictly convex (ReflexCorners). A corner
/// that is no ear because of a corner j of S stays none until j leaves S (is clipped or turns
/// convex: then the corner waits in `recheck_`); one that is no ear by its own shape stays
/// none until a neighbour changes. So when no ear is known (`ears_` empty), retesting only
/// `recheck_` finds exactly the ears that testing every corner would find, and the clipping
/// order, hence every triangle, is that of the plain algorithm, in O(n log n) for polygons
/// whose corners are spread evenly (one 40,000-corner polygon: milliseconds, not 30 s).
/// A polygon that crosses itself runs out of ears now and then; its fallback corner, the
/// most convex one, comes from an ordered set of every live corner's turn, built at the
/// first fallback and kept up to date from then on (a scan of every corner per fallback
/// made such polygons quadratic).
class EarClipper {
public:
    EarClipper(const std::vector<Vec3d>& p, const std::vector<int>& ids, Projection proj, std::vector<Int3>& out)
        : p_(p), ids_(ids), proj_(proj), out_(out), prev_(p.size()), next_(p.size()), alive_(p.size(), true),
          key_(p.size(), -1.0), blocked_(p.size()), reflex_(p, proj, start_links()), monitor_(current_task_monitor()) {
        left_ = int(p.size());
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
                if (!tracking_turns_) track_turns();
                tip = turns_.begin()->second;
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

    /// Links every corner to its neighbours; returns the corners that are not strictly convex.
    std::vector<int> start_links() {
        const int n = int(p_.size());
        for (int i = 0; i < n; ++i) { prev_[size_t(i)] = (i + n - 1) % n; next_[size_t(i)] = (i + 1) % n; }
        std::vector<int> reflex;
        for (int i = 0; i < n; ++i)
            if (!convex(i)) reflex.push_back(i);
        return reflex;
    }

    void clip(int tip) {
        const int a = prev_[size_t(tip)], c = next_[size_t(tip)];
        emit(a, tip, c);
        forget(tip);
        untrack_turn(tip);
        alive_[size_t(tip)] = false;
        leave_reflex(tip);
        next_[size_t(a)] = c;
        prev_[size_t(c)] = a;
        --left_;
        for (const int corner : {a, c}) {
            // In a polygon that is not simple, a corner may turn either way.
            if (!convex(corner)) reflex_.insert(corner);
            else leave_reflex(corner);
        }
        update(a);
        update(c);
        if (tracking_turns_)
            for (const int corner : {a, c}) { untrack_turn(corner); track_turn(corner); }
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

    /// How much corner i turns the polygon's way; the fallback clips the corner that turns
    /// the most, the first of equals (it may hold other corners). A turn that overflowed to
    /// NaN counts as the least.
    double turn(int i) const {
        const double t = proj_.orient(p_[size_t(prev_[size_t(i)])], p_[size_t(i)], p_[size_t(next_[size_t(i)])]);
        return std::isnan(t) ? -std::numeric_limits<double>::infinity() : t;
    }

    void track_turns() {
        tracking_turns_ = true;
        turn_key_.assign(p_.size(), 0.0);
        for (int i = 0; i < int(p_.size()); ++i)
            if (alive_[size_t(i)]) track_turn(i);
    }

    void track_turn(int i) {
        turn_key_[size_t(i)] = -turn(i);
        turns_.insert({turn_key_[size_t(i)], i});
    }

    void untrack_turn(int i) {
        if (tracking_turns_) turns_.erase({turn_key_[size_t(i)], i});
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
    std::set<std::pair<double, int>> turns_;  ///< (-turn, corner) of every live corner, once a fallback was needed
    std::vector<double> turn_key_;            ///< each corner's key in turns_
    bool tracking_turns_ = false;
    ReflexCorners reflex_;                    ///< S: live corners not strictly convex
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
