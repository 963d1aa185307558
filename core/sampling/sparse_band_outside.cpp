// The sparse band's outside: the octree over the inactive blocks (OutsideClassifier) and the
// uniform cells' sides from their neighbours (CellFlood).
#include "core/sampling/sparse_band_outside.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <new>
#include <utility>

#include "core/mesh/prepared_mesh.h"
#include "core/parallel/parallel_for.h"
#include "core/winding/winding_sign.h"
#include "kernels/winding/certified_winding.h"

namespace sdf {

std::vector<BoundaryEdge> boundary_edges(const PreparedMesh& mesh) {
    std::vector<std::pair<uint64_t, int>> uses;
    uses.reserve(mesh.triangles().size() * 3);
    for (const Int3& t : mesh.triangles())
        for (int e = 0; e < 3; ++e) {
            const uint32_t a = uint32_t(t[e]), b = uint32_t(t[(e + 1) % 3]);
            uses.push_back({a < b ? (uint64_t(a) << 32 | b) : (uint64_t(b) << 32 | a), a < b ? 1 : -1});
        }
    std::sort(uses.begin(), uses.end());
    std::vector<BoundaryEdge> out;
    for (size_t i = 0; i < uses.size();) {
        size_t j = i;
        int net = 0;
        for (; j < uses.size() && uses[j].first == uses[i].first; ++j) net += uses[j].second;
        if (net != 0) {
            const Vec3d a = mesh.vertices()[size_t(uses[i].first >> 32)], b = mesh.vertices()[size_t(uses[i].first & 0xffffffffu)];
            out.push_back({a, b, std::abs(net) * length(b - a)});
        }
        i = j;
    }
    return out;
}

namespace {


double point_segment_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
    const Vec3d ab = b - a;
    const double l2 = dot(ab, ab);
    const double t = l2 > 0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
    return length(p - (a + ab * t));
}


/// A bit per block, set and read by several threads at once (GCC's atomic built-ins on plain
/// words; relaxed unless asked: a reader that sees a bit sees it set for good). The words come
/// from calloc, whose large blocks are zero pages until written: at 8192^3 the two arrays of
/// the flood below span 268 MB, of which it touches the few pages near the band.
class AtomicBlockBits {
public:
    explicit AtomicBlockBits(int64_t n) : bits_(static_cast<uint64_t*>(std::calloc(size_t((n + 63) / 64) + 1, sizeof(uint64_t)))) {
        if (!bits_) throw std::bad_alloc();
    }
    bool get(int64_t i, int order = __ATOMIC_RELAXED) const { return (__atomic_load_n(&bits_.get()[i >> 6], order) >> (i & 63)) & 1; }
    void set(int64_t i, int order = __ATOMIC_RELAXED) { __atomic_fetch_or(&bits_.get()[i >> 6], uint64_t(1) << (i & 63), order); }

private:
    struct Free {
        void operator()(uint64_t* p) const { std::free(p); }
    };
    std::unique_ptr<uint64_t[], Free> bits_;
};

/// The sides of the outside's uniform cells from their neighbours, where the band is at least a
/// coset spacing wide: a point of an inactive block lies farther than W from the surface, so it
/// and its neighbour h away lie farther than W - h >= 0 from it along the step between them,
/// on one side (band_sides.h's argument), and the sign is the side of the solid or of the
/// closed mesh's winding number. A cell takes the side of the point next to one of its own
/// across a face: an active block's (the sign of the band's value there) or a signed cell's.
/// Sweeps over the cells still unsigned, forward and backward in turn, until one signs none
/// (a cell signed early in a sweep signs the cells after it), each sweep's cells in chunks on
/// every thread: a side once set never changes and every side set is the cell's own, so which
/// thread sets it first does not matter, and the cells left unsigned (none reaches them) are
/// the same whatever the order. A neighbour that is a whole first cell (16^3 blocks,
/// OutsideClassifier's) is looked at once per row of the face.
class CellFlood {
public:
    static constexpr int kFirst = 16;  ///< blocks per axis of OutsideClassifier's first cells

    CellFlood(const BandLayout& layout, const BlockBits& active, const std::vector<Cell>& cells, const SparseBandField& band)
        : layout_(layout), active_(active), cells_(cells), band_(band), side_(cells.size()), signed_(layout.block_count()),
          inside_(layout.block_count()) {
        for (auto& s : side_) s.store(-1, std::memory_order_relaxed);
        int64_t n = 0;
        for (int c = 0; c < layout.cosets(); ++c) {
            const Int3 b = layout.coset(c).blocks;
            first_offset_.push_back(n);
            first_grid_.push_back({(b.x + kFirst - 1) / kFirst, (b.y + kFirst - 1) / kFirst, (b.z + kFirst - 1) / kFirst});
            n += int64_t(first_grid_.back().x) * first_grid_.back().y * first_grid_.back().z;
        }
        whole_.assign(size_t(n), -1);
        for (size_t k = 0; k < cells.size(); ++k)
            if (is_first_cell(cells[k])) whole_[size_t(first_of(cells[k].coset, cells[k].lo))] = int64_t(k);
    }

    /// side(k): 1 inside, 0 outside, -1 left to a query.
    void run(int threads) {
        std::vector<size_t> open(cells_.size());
        for (size_t k = 0; k < open.size(); ++k) open[k] = k;
        constexpr int64_t kChunk = 4096;
        for (bool forward = true; !open.empty(); forward = !forward) {
            const int64_t n = int64_t(open.size());
            std::vector<char> still(open.size(), 0);
            parallel_for(n, kChunk, threads, [&](int64_t begin, int64_t end) {
                for (int64_t m = begin; m < end; ++m) {
                    const size_t i = size_t(forward ? m : n - 1 - m);
                    const size_t k = open[i];
                    const int side = side_beside(cells_[k]);
                    if (side < 0) {
                        still[i] = 1;
                        continue;
                    }
                    const Cell& c = cells_[k];
                    if (!is_first_cell(c))  // the side bit before the release that publishes it
                        for (int z = c.lo.z; z < c.hi.z; ++z)
                            for (int y = c.lo.y; y < c.hi.y; ++y)
                                for (int x = c.lo.x; x < c.hi.x; ++x) {
                                    const int64_t id = layout_.block_id(c.coset, {x, y, z});
                                    if (side == 1) inside_.set(id);
                                    signed_.set(id, __ATOMIC_RELEASE);
                                }
                    side_[k].store(static_cast<signed char>(side), std::memory_order_relaxed);
                }
            });
            std::vector<size_t> left;
            for (size_t i = 0; i < open.size(); ++i)
                if (still[i]) left.push_back(open[i]);
            if (left.size() == open.size()) break;
            open.swap(left);
        }
    }

    int side(size_t k) const { return side_[k].load(std::memory_order_relaxed); }

private:
    int64_t first_of(int coset, const Int3& block) const {
        const Int3 g = first_grid_[size_t(coset)];
        return first_offset_[size_t(coset)] + block.x / kFirst + int64_t(g.x) * (block.y / kFirst + int64_t(g.y) * (block.z / kFirst));
    }
    bool is_first_cell(const Cell& c) const {
        const Int3 n = layout_.coset(c.coset).blocks;
        for (int a = 0; a < 3; ++a)
            if (c.lo[a] % kFirst != 0 || c.hi[a] != std::min(c.lo[a] + kFirst, n[a])) return false;
        return true;
    }

    /// The side of cell c from a neighbour across one of its faces, or -1. The points are real:
    /// the neighbour's is its block's first along the axis (beyond the high face) or its last
    /// (below the low face, where its block is not the coset's last), the cell's likewise, and
    /// every other coordinate is its block's first.
    int side_beside(const Cell& c) const {
        const Int3 blocks = layout_.coset(c.coset).blocks;
        for (int axis = 0; axis < 3; ++axis)
            for (const bool high : {false, true}) {
                if (high ? c.hi[axis] >= blocks[axis] : c.lo[axis] == 0) continue;
                const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
                for (int j = c.lo[v]; j < c.hi[v]; ++j)
                    for (int i = c.lo[u]; i < c.hi[u]; ++i) {
                        Int3 b{};
                        b[axis] = high ? c.hi[axis] : c.lo[axis] - 1;
                        b[u] = i;
                        b[v] = j;
                        const int64_t whole = whole_[size_t(first_of(c.coset, b))];
                        if (whole >= 0) {
                            const int side = side_[size_t(whole)].load(std::memory_order_relaxed);
                            if (side >= 0) return side;
                            i = std::min(c.hi[u], (i / kFirst + 1) * kFirst) - 1;  // the rest of that first cell in this row
                            continue;
                        }
                        const int64_t id = layout_.block_id(c.coset, b);
                        if (signed_.get(id, __ATOMIC_ACQUIRE)) return inside_.get(id) ? 1 : 0;
                        if (!active_.get(id)) continue;
                        Int3 local{0, 0, 0};
                        local[axis] = high ? 0 : kBandBlockDim - 1;
                        const size_t index = size_t(band_.find_active(id)) * kBandBlockPoints +
                                             size_t(local.x + kBandBlockDim * (local.y + kBandBlockDim * local.z));
                        return std::signbit(band_.distance[index]) ? 1 : 0;
                    }
            }
        return -1;
    }

    const BandLayout& layout_;
    const BlockBits& active_;
    const std::vector<Cell>& cells_;
    const SparseBandField& band_;
    std::vector<std::atomic<signed char>> side_;
    AtomicBlockBits signed_, inside_;    ///< the blocks of signed cells that are not whole first cells, and their sides
    std::vector<int64_t> first_offset_;  ///< each coset's first first cell
    std::vector<Int3> first_grid_;       ///< each coset's first cells per axis
    std::vector<int64_t> whole_;         ///< each first cell that is one uniform cell: its index, else -1
};

class OutsideClassifier {
public:
    OutsideClassifier(const BandLayout& layout, const BlockBits& active, OutsideRule rule, const WindingSign* winding,
                      const PreparedMesh& mesh, std::vector<BoundaryEdge> edges)
        : layout_(layout), active_(active), rule_(rule), winding_(winding), edges_(std::move(edges)) {
        if (winding_) view_ = winding_->winding_bvh().view<double>(mesh);
    }

    OutsideCells cells;

    /// The first cells (16^3 blocks) on `threads` threads, each run of them into its own lists,
    /// joined in the cells' order: the lists are the one-thread walk's whatever the thread
    /// count (at 8192^3, 262,144 first cells over 1.07G blocks took 2 s on one thread).
    void run(int threads) {
        const int top = 16;  // blocks per axis of the first cells
        std::vector<Cell> first;
        for (int c = 0; c < layout_.cosets(); ++c) {
            const Int3 n = layout_.coset(c).blocks;
            for (int z = 0; z < n.z; z += top)
                for (int y = 0; y < n.y; y += top)
                    for (int x = 0; x < n.x; x += top)
                        first.push_back({c, {x, y, z}, {std::min(x + top, n.x), std::min(y + top, n.y), std::min(z + top, n.z)}});
        }
        constexpr int64_t kRun = 64;  // first cells per run
        const int64_t runs = (int64_t(first.size()) + kRun - 1) / kRun;
        std::vector<Found> found(static_cast<size_t>(runs));
        parallel_for(runs, 1, threads, [&](int64_t r0, int64_t r1) {
            for (int64_t r = r0; r < r1; ++r)
                for (int64_t i = r * kRun; i < std::min<int64_t>(int64_t(first.size()), (r + 1) * kRun); ++i)
                    visit(first[size_t(i)], found[size_t(r)]);
        });
        for (const Found& f : found) {
            cells.uniform.insert(cells.uniform.end(), f.uniform.begin(), f.uniform.end());
            cells.per_point.insert(cells.per_point.end(), f.per_point.begin(), f.per_point.end());
            cells.refused_by_evaluation += f.refused_by_evaluation;
            cells.refused_by_gradient += f.refused_by_gradient;
        }
        std::sort(cells.per_point.begin(), cells.per_point.end());
    }

private:
    /// What a run of first cells found.
    struct Found {
        std::vector<Cell> uniform;
        std::vector<int64_t> per_point;
        int64_t refused_by_evaluation = 0, refused_by_gradient = 0;
    };

    void visit(const Cell& cell, Found& out) const {
        int64_t count = 0, active = 0;
        for (int z = cell.lo.z; z < cell.hi.z; ++z)
            for (int y = cell.lo.y; y < cell.hi.y; ++y)
                for (int x = cell.lo.x; x < cell.hi.x; ++x) {
                    ++count;
                    active += active_.get(layout_.block_id(cell.coset, {x, y, z})) ? 1 : 0;
                }
        if (active == count) return;
        if (active == 0 && proven_uniform(cell, out)) {
            out.uniform.push_back(cell);
            return;
        }
        if (count == 1) {
            out.per_point.push_back(layout_.block_id(cell.coset, cell.lo));
            return;
        }
        const Int3 mid{(cell.lo.x + cell.hi.x + 1) / 2, (cell.lo.y + cell.hi.y + 1) / 2, (cell.lo.z + cell.hi.z + 1) / 2};
        for (int k = 0; k < 8; ++k) {
            Cell child{cell.coset, cell.lo, cell.hi};
            for (int a = 0; a < 3; ++a) {
                if (mid[a] >= cell.hi[a]) {  // an extent of one block is not split
                    if (k >> a & 1) child.hi[a] = child.lo[a];
                    continue;
                }
                if (k >> a & 1) child.lo[a] = mid[a];
                else child.hi[a] = mid[a];
            }
            if (child.lo.x < child.hi.x && child.lo.y < child.hi.y && child.lo.z < child.hi.z) visit(child, out);
        }
    }

    bool proven_uniform(const Cell& cell, Found& out) const {
        switch (rule_) {
            case OutsideRule::Uniform: return true;
            case OutsideRule::PerPoint: return false;
            case OutsideRule::WindingBound: break;
        }
        Vec3d lo, hi, unused;
        layout_.cell_box(layout_.block_id(cell.coset, cell.lo), lo, unused);
        layout_.cell_box(layout_.block_id(cell.coset, {cell.hi.x - 1, cell.hi.y - 1, cell.hi.z - 1}), unused, hi);
        const Vec3d centre = (lo + hi) * 0.5;
        const double delta = 0.5 * length(hi - lo);
        // The certified evaluation (its bound covers truncation and rounding, as the sign's
        // certification uses it), pessimistic where worst cases sum: a larger beta where it
        // does not decide, as WindingSign's refinement does.
        WindingAccuracy<double> accuracy = winding_->options().accuracy;
        WindingEstimate<double> w = certified_winding_number(view_, centre, accuracy);
        for (int k = 0; k < 3 && !(std::abs(w.value - 0.5) > w.error_bound + 0.05); ++k) {
            accuracy.beta *= 3;
            w = certified_winding_number(view_, centre, accuracy);
        }
        const double room = std::abs(w.value - 0.5) - w.error_bound - 1e-9;  // what w may change by in the cell
        if (!(room > 0)) {
            ++out.refused_by_evaluation;
            return false;
        }
        const double limit = room * 4 * 3.14159265358979323846 / delta;  // on 4 pi |grad w| (Biot-Savart)
        double g = 0;
        for (const BoundaryEdge& e : edges_) {
            const double d = point_segment_distance(centre, e.a, e.b) - delta;
            g += d > 0 ? e.weight / (d * d) : limit;
            if (!(g < limit)) {
                ++out.refused_by_gradient;
                return false;
            }
        }
        return true;
    }

    const BandLayout& layout_;
    const BlockBits& active_;
    OutsideRule rule_;
    const WindingSign* winding_;
    WindingView<double> view_{};  ///< the winding data's view, for the certified evaluation
    std::vector<BoundaryEdge> edges_;
};

}  // namespace

OutsideCells classify_outside(const BandLayout& layout, const BlockBits& active, OutsideRule rule, const WindingSign* winding,
                              const PreparedMesh& mesh, std::vector<BoundaryEdge> edges, int threads) {
    OutsideClassifier classify(layout, active, rule, winding, mesh, std::move(edges));
    classify.run(threads);
    return std::move(classify.cells);
}

std::vector<signed char> cell_sides_from_neighbours(const BandLayout& layout, const BlockBits& active,
                                                    const std::vector<Cell>& cells, const SparseBandField& band, int threads) {
    CellFlood flood(layout, active, cells, band);
    flood.run(threads);
    std::vector<signed char> sides(cells.size());
    for (size_t k = 0; k < cells.size(); ++k) sides[k] = static_cast<signed char>(flood.side(k));
    return sides;
}

}  // namespace sdf
