#include "core/sampling/sparse_band_sampler.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/host_memory.h"
#include "core/lattice/lattice_fitting.h"
#include "core/parallel/parallel_for.h"
#include "core/sampling/sampler.h"
#include "core/sampling/sampler_sign.h"
#include "core/sampling/search_range.h"
#include "core/winding/winding_sign.h"
#include "kernels/winding/certified_winding.h"

namespace sdf {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// A bit per block.
class BlockBits {
public:
    explicit BlockBits(int64_t n) : bits_(size_t((n + 63) / 64), 0) {}
    bool get(int64_t i) const { return (bits_[size_t(i >> 6)] >> (i & 63)) & 1; }
    void set(int64_t i) { bits_[size_t(i >> 6)] |= uint64_t(1) << (i & 63); }
    /// The set bits, ascending, a word at a time: at 4096^3 (134M blocks, 1.4M set) a bit at a
    /// time took 0.13-0.16 s of CPU on the dragon, this 0.045 s.
    std::vector<int64_t> set_bits() const {
        std::vector<int64_t> out;
        out.reserve(size_t(count()));
        for (size_t w = 0; w < bits_.size(); ++w)
            for (uint64_t b = bits_[w]; b != 0; b &= b - 1) out.push_back(int64_t(w) * 64 + __builtin_ctzll(b));
        return out;
    }
    int64_t count() const {
        int64_t n = 0;
        for (const uint64_t w : bits_) n += __builtin_popcountll(w);
        return n;
    }

private:
    std::vector<uint64_t> bits_;
};

/// Step 1: the blocks whose cells meet a triangle's box dilated by W and the slab within W of its plane.
BlockBits active_blocks(const PreparedMesh& mesh, const BandLayout& layout, double width) {
    BlockBits bits(layout.block_count());
    const Lattice& lattice = layout.lattice();
    const double h = lattice.spacing;
    const double dilation = width * (1 + 1e-9) + 1e-4 * h;
    const double eps = 1e-4;  // in spacings: the rounding of u below
    const std::vector<Vec3d>& v = mesh.vertices();
    for (int c = 0; c < layout.cosets(); ++c) {
        const BandCoset& s = layout.coset(c);
        const Vec3d o = lattice.position_of_coords(s.first);
        for (const Int3& t : mesh.triangles()) {
            int lo[3], hi[3];
            bool empty = false;
            for (int a = 0; a < 3; ++a) {
                const double tlo = std::min({v[size_t(t.x)][a], v[size_t(t.y)][a], v[size_t(t.z)][a]}) - dilation;
                const double thi = std::max({v[size_t(t.x)][a], v[size_t(t.y)][a], v[size_t(t.z)][a]}) + dilation;
                // Coset index u = (x - o) / h; block b's cell covers u in [8b, 8b + 8].
                const double ulo = (tlo - o[a]) / h - eps, uhi = (thi - o[a]) / h + eps;
                const double blo = std::ceil(ulo / kBandBlockDim - 1), bhi = std::floor(uhi / kBandBlockDim);
                const int n = s.blocks[a];
                lo[a] = int(std::max(0.0, std::min(blo, double(n))));
                hi[a] = int(std::max(-1.0, std::min(bhi, double(n - 1))));
                empty = empty || lo[a] > hi[a];
            }
            if (empty) continue;
            // Of those, the cells that meet the slab within W of the triangle's plane: a
            // triangle across its box (a diagonal one) leaves most of the box's cells beyond W.
            // Conservative: the cell's distance to the plane, |n.(centre - V0)| less the cell's
            // half extent along n, is taken within the dilation plus 1e-4 spacings and 2^-40 of
            // the magnitudes (the rounding of n and the dot products). A degenerate triangle
            // (no normal) keeps its box.
            const Vec3d a = v[size_t(t.x)], e0 = v[size_t(t.y)] - a, e1 = v[size_t(t.z)] - a;
            const Vec3d normal = cross(e0, e1);
            const double area2 = length(normal);
            // The normal's direction is off by about u |E0| |E1| / |E0 x E1| (a sliver's cross
            // product cancels): that times the cell's distance from V0 is added to the reach;
            // past 1e-3 rad (an extreme sliver) the box alone decides.
            const double tilt = 8 * 0x1p-53 * length(e0) * length(e1) / area2 + 8 * 0x1p-53;
            const bool slab = area2 > 0 && std::isfinite(area2) && tilt < 1e-3;
            const Vec3d n = slab ? normal / area2 : Vec3d(0.0);
            const double half = 0.5 * kBandBlockDim * h * (std::abs(n.x) + std::abs(n.y) + std::abs(n.z));
            const double magnitude = std::abs(a.x) + std::abs(a.y) + std::abs(a.z) + std::abs(o.x) + std::abs(o.y) + std::abs(o.z) +
                                     3 * kBandBlockDim * h * (double(s.blocks.x) + s.blocks.y + s.blocks.z);
            const double reach = dilation + half + 1e-4 * h + 0x1p-40 * magnitude;
            for (int z = lo[2]; z <= hi[2]; ++z)
                for (int y = lo[1]; y <= hi[1]; ++y)
                    for (int x = lo[0]; x <= hi[0]; ++x) {
                        if (slab) {
                            const double cell = 0.5 * kBandBlockDim * h;  // the cell's centre, from its first point
                            const Vec3d centre{o.x + (kBandBlockDim * x) * h + cell, o.y + (kBandBlockDim * y) * h + cell,
                                               o.z + (kBandBlockDim * z) * h + cell};
                            const Vec3d from = centre - a;
                            if (std::abs(dot(n, from)) > reach + tilt * (length(from) + kBandBlockDim * h)) continue;
                        }
                        bits.set(layout.block_id(c, {x, y, z}));
                    }
        }
    }
    return bits;
}

/// The mesh's boundary edges with their net oriented uses (non-zero): the sources of the
/// winding number's gradient.
struct BoundaryEdge {
    Vec3d a, b;
    double weight;  ///< |net uses| x length
};

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

double point_segment_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
    const Vec3d ab = b - a;
    const double l2 = dot(ab, ab);
    const double t = l2 > 0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
    return length(p - (a + ab * t));
}

/// How the side of a cell without surface is decided (see the header).
enum class OutsideRule { Uniform, WindingBound, PerPoint };

struct Cell {
    int coset;
    Int3 lo, hi;  ///< block range [lo, hi)
};

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

    std::vector<Cell> uniform;      ///< cells of inactive blocks with one side
    std::vector<int64_t> per_point; ///< inactive blocks queried at every point
    int64_t refused_by_evaluation = 0;  ///< cells whose |w~ - 1/2| is within the evaluation's bound
    int64_t refused_by_gradient = 0;    ///< cells where w may cross 1/2 by the Biot-Savart bound

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
            uniform.insert(uniform.end(), f.uniform.begin(), f.uniform.end());
            per_point.insert(per_point.end(), f.per_point.begin(), f.per_point.end());
            refused_by_evaluation += f.refused_by_evaluation;
            refused_by_gradient += f.refused_by_gradient;
        }
        std::sort(per_point.begin(), per_point.end());
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

/// Queries `points` (lattice positions) in batches; f(first, results) per batch.
template <typename F>
void query_in_batches(const BoundSampler& sampler, const std::vector<Vec3d>& points, int64_t batch, SamplingTimings& total,
                      F&& f) {
    for (size_t first = 0; first < points.size(); first += size_t(batch)) {
        const size_t last = std::min(points.size(), first + size_t(batch));
        const std::vector<Vec3d> part(points.begin() + long(first), points.begin() + long(last));
        SamplingTimings t;
        const std::vector<PointSample> r = sampler.query(part, &t);
        total.kernel += t.kernel;
        total.upload += t.upload;
        total.download += t.download;
        total.certified_points += t.certified_points;
        total.reranked_points += t.reranked_points;
        total.full_double_points += t.full_double_points;
        f(first, r);
    }
}

}  // namespace

SparseBandField sample_sparse_band(const BoundSampler& sampler, const Lattice& lattice, double width,
                                   const SparseBandPlan& plan, const BandBlockKernel& blocks) {
    const Clock::time_point start = Clock::now();
    const PreparedMesh& mesh = sampler.mesh();
    require_search_range(mesh, lattice, plan.precision);
    if (plan.batch_points < kBandBlockPoints)
        throw std::invalid_argument("sparse band: batch_points must be at least " + std::to_string(kBandBlockPoints));
    // Every size is checked before it is allocated: first the two bitsets of one bit per
    // block (the active blocks, the inside tiles: 2 x 128 MiB at 8192^3), then, once the
    // active blocks are known, their channels.
    const std::string what = "the sparse band of " + lattice_notation(lattice);
    require_host_bytes(2 * uint64_t((BandLayout(lattice).block_count() + 63) / 64) * sizeof(uint64_t),
                       what + " (its per-block bitsets)");
    SparseBandField out(lattice, width, plan.precision, plan.channels);
    const BandLayout& layout = out.layout();
    nlohmann::json steps = nlohmann::json::object();

    // 1. Active blocks.
    Clock::time_point t = Clock::now();
    const BlockBits active = active_blocks(mesh, layout, width);
    const int64_t active_count = active.count();
    const uint64_t point_bytes = band_distance_type(plan.channels.distance_type).bytes + (plan.channels.gradient ? sizeof(Vec3d) : 0) +
                                 (plan.channels.closest_triangle ? sizeof(int32_t) : 0);
    require_host_bytes(uint64_t(active_count) * (kBandBlockPoints * point_bytes + sizeof(BandPointMask) + sizeof(int64_t)),
                       what + ": " + std::to_string(active_count) + " active blocks of " +
                           std::to_string(kBandBlockPoints) + " points, " + std::to_string(point_bytes) +
                           " bytes a point (" + channel_names(plan.channels).dump() + ")");
    out.active = active.set_bits();
    steps["find_blocks_seconds"] = seconds_since(t);

    // 2. Their points, batch by batch (batches of whole blocks).
    t = Clock::now();
    const size_t values = out.active.size() * kBandBlockPoints;
    const int64_t blocks_per_batch = plan.batch_points / kBandBlockPoints;
    int64_t points_computed = 0;
    if (blocks) {
        // The kernel writes every lattice point's values: allocated, not written (the fill
        // and the pages' first touch cost what a GPU's kernels do, 36 bytes a point), but
        // for the padding of the blocks at the lattice's far edges.
        out.distance.resize(values);
        if (plan.channels.gradient) out.gradient.resize(values);
        if (plan.channels.closest_triangle) out.closest_triangle.resize(values);
        out.band_mask.resize(out.active.size());  // the kernel writes every block's
        for (size_t a = 0; a < out.active.size(); ++a) {
            const BandBlockCoords b = layout.block_coords(out.active[a]);
            const Int3 n = layout.coset(b.coset).points;
            Int3 r{};
            for (int k = 0; k < 3; ++k) r[k] = std::min(kBandBlockDim, n[k] - b.block[k] * kBandBlockDim);
            points_computed += int64_t(r.x) * r.y * r.z;
            if (r.x == kBandBlockDim && r.y == kBandBlockDim && r.z == kBandBlockDim) continue;
            for (int local = 0; local < kBandBlockPoints; ++local) {
                const Int3 p = BandLayout::local_offset(local);
                if (p.x < r.x && p.y < r.y && p.z < r.z) continue;
                const size_t v = a * kBandBlockPoints + size_t(local);
                out.distance.set(v, width);
                if (plan.channels.gradient) out.gradient[v] = Vec3d(0.0);
                if (plan.channels.closest_triangle) out.closest_triangle[v] = kOutsideBandTriangle;
            }
        }
        // One call for every block: the kernel batches as its memory allows (a GPU uploads
        // the ids once).
        if (!out.active.empty()) blocks(out, 0, out.active.size());
    } else {
        out.distance.assign(values, width);
        if (plan.channels.gradient) out.gradient.assign(values, Vec3d(0.0));
        if (plan.channels.closest_triangle) out.closest_triangle.assign(values, kOutsideBandTriangle);
        out.band_mask.assign(out.active.size(), BandPointMask{});
    }
    for (size_t first = 0; !blocks && first < out.active.size(); first += size_t(blocks_per_batch)) {
        const size_t last = std::min(out.active.size(), first + size_t(blocks_per_batch));
        std::vector<Vec3d> points;
        std::vector<size_t> slot;  // value index of each point
        points.reserve((last - first) * kBandBlockPoints);
        slot.reserve((last - first) * kBandBlockPoints);
        for (size_t a = first; a < last; ++a)
            for (int local = 0; local < kBandBlockPoints; ++local) {
                if (layout.storage_index(out.active[a], local) < 0) continue;
                points.push_back(lattice.position_of_coords(layout.point_coords(out.active[a], local)));
                slot.push_back(a * kBandBlockPoints + size_t(local));
            }
        points_computed += int64_t(points.size());
        query_in_batches(sampler, points, int64_t(points.size()) + 1, out.timings, [&](size_t, const std::vector<PointSample>& r) {
            for (size_t i = 0; i < r.size(); ++i) {
                const size_t v = slot[i];
                if (outside_band(r[i].distance, width)) {
                    out.distance.set(v, std::signbit(r[i].distance) ? -width : width);  // store_outside_band's values
                } else {
                    out.distance.set(v, r[i].distance);
                    if (plan.channels.gradient) out.gradient[v] = r[i].gradient;
                    if (plan.channels.closest_triangle) out.closest_triangle[v] = r[i].triangle;
                    set_mask_bit(out.band_mask[v / kBandBlockPoints], int(v % kBandBlockPoints));
                }
            }
        });
    }
    steps["active_points_seconds"] = seconds_since(t);
    steps["active_points_by"] = blocks ? "the backend's block kernel" : "point queries";

    // 3. The outside.
    t = Clock::now();
    const SignModeChoice& sign = sampler.sign();
    const bool solid = choose_sign_mode(mesh.report(), SignMode::Auto).mode == SignMode::Pseudonormal;
    std::vector<BoundaryEdge> edges;
    std::unique_ptr<WindingSign> winding;
    OutsideRule rule = OutsideRule::Uniform;
    if (sign.mode == SignMode::Winding) {
        edges = boundary_edges(mesh);
        if (!edges.empty()) {
            rule = OutsideRule::WindingBound;
            winding = std::make_unique<WindingSign>(mesh, mesh.bvh(), SamplerSign::winding_options());
        }
    } else if (!solid) {
        rule = OutsideRule::PerPoint;
    }
    const size_t boundary_edge_count = edges.size();
    OutsideClassifier classify(layout, active, rule, winding.get(), mesh, std::move(edges));
    classify.run(plan.threads);
    const auto sign_cell = [&](const Cell& c, bool inside) {
        if (!inside) return;  // tiles start outside
        for (int z = c.lo.z; z < c.hi.z; ++z)
            for (int y = c.lo.y; y < c.hi.y; ++y)
                for (int x = c.lo.x; x < c.hi.x; ++x) out.set_tile_inside(layout.block_id(c.coset, {x, y, z}), true);
    };
    // The uniform cells' sides from their neighbours (CellFlood), where the band is at least a
    // coset spacing wide and the sign is uniform off the surface; the others are queried, one
    // point each, at their first block's first point.
    std::vector<const Cell*> queried;
    int64_t cells_beside_the_band = 0;
    if (rule == OutsideRule::Uniform && width >= lattice.spacing) {
        CellFlood flood(layout, active, classify.uniform, out);
        flood.run(plan.threads);
        for (size_t k = 0; k < classify.uniform.size(); ++k) {
            if (flood.side(k) < 0) {
                queried.push_back(&classify.uniform[k]);
                continue;
            }
            sign_cell(classify.uniform[k], flood.side(k) == 1);
            ++cells_beside_the_band;
        }
    } else {
        for (const Cell& c : classify.uniform) queried.push_back(&c);
    }
    std::vector<Vec3d> reps;
    reps.reserve(queried.size());
    for (const Cell* c : queried) reps.push_back(lattice.position_of_coords(layout.point_coords(layout.block_id(c->coset, c->lo), 0)));
    query_in_batches(sampler, reps, plan.batch_points, out.timings, [&](size_t first, const std::vector<PointSample>& r) {
        for (size_t i = 0; i < r.size(); ++i) sign_cell(*queried[first + i], std::signbit(r[i].distance));
    });
    // Blocks not proven uniform: every point's side, batch by batch; a block whose sides all
    // agree becomes a tile.
    int64_t per_point_points = 0;
    for (size_t first = 0; first < classify.per_point.size(); first += size_t(blocks_per_batch)) {
        const size_t last = std::min(classify.per_point.size(), first + size_t(blocks_per_batch));
        std::vector<Vec3d> points;
        std::vector<std::pair<size_t, int>> where;
        for (size_t b = first; b < last; ++b)
            for (int local = 0; local < kBandBlockPoints; ++local) {
                if (layout.storage_index(classify.per_point[b], local) < 0) continue;
                points.push_back(lattice.position_of_coords(layout.point_coords(classify.per_point[b], local)));
                where.push_back({b, local});
            }
        per_point_points += int64_t(points.size());
        std::vector<BandSignMask> masks(last - first, BandSignMask{});
        std::vector<int> inside(last - first, 0), total(last - first, 0);
        query_in_batches(sampler, points, int64_t(points.size()) + 1, out.timings, [&](size_t, const std::vector<PointSample>& r) {
            for (size_t i = 0; i < r.size(); ++i) {
                const size_t b = where[i].first - first;
                const int local = where[i].second;
                ++total[b];
                if (!std::signbit(r[i].distance)) continue;
                ++inside[b];
                masks[b][size_t(local >> 6)] |= uint64_t(1) << (local & 63);
            }
        });
        for (size_t b = first; b < last; ++b) {
            const int64_t id = classify.per_point[b];
            if (inside[b - first] == 0 || inside[b - first] == total[b - first]) {
                out.set_tile_inside(id, inside[b - first] > 0);
            } else {
                out.mixed_inside[size_t(out.add_mixed(id))] = masks[b - first];
            }
        }
    }
    steps["outside_seconds"] = seconds_since(t);

    // The report: the dense band's keys, and the sparse steps' counts.
    const SparseBandCounts counts = out.counts();
    BandReport band;
    band.width = width;
    band.points_in_band = counts.band_points;
    band.points_outside = lattice.num_points() - counts.band_points;
    band.how = "sparse: active blocks sampled, the outside signed per cell";
    out.sampler.backend = sampler.name();
    out.sampler.precision = precision_name(plan.precision);
    out.sampler.points_computed = points_computed + int64_t(reps.size()) + per_point_points;
    out.sampler.band = band;
    out.sampler.details["sign"] = {{"mode", sign_mode_name(sign.mode)}, {"reason", sign.reason}};
    const char* rule_name = rule == OutsideRule::Uniform ? "uniform off the surface"
                            : rule == OutsideRule::WindingBound ? "winding number bound (Biot-Savart)"
                                                                : "every point";
    out.sampler.details["sparse_band"] = {{"block", kBandBlockDim},
                                          {"blocks", counts.blocks},
                                          {"active_blocks", counts.active_blocks},
                                          {"active_points", counts.active_points},
                                          {"mixed_blocks", counts.mixed_blocks},
                                          {"tiles", counts.tiles},
                                          {"inside_tiles", counts.inside_tiles},
                                          {"uniform_cells", int64_t(classify.uniform.size())},
                                          {"uniform_cells_beside_the_band", cells_beside_the_band},
                                          {"cells_refused_by_evaluation", classify.refused_by_evaluation},
                                          {"cells_refused_by_gradient", classify.refused_by_gradient},
                                          {"points_signed_per_point", per_point_points},
                                          {"outside_rule", rule_name},
                                          {"channels", channel_names(plan.channels)},
                                          {"distance_type", band_distance_type(plan.channels.distance_type).name},
                                          {"boundary_edges", int64_t(boundary_edge_count)},
                                          {"steps", steps},
                                          {"memory_bytes", int64_t(out.memory_bytes())}};
    out.timings.total = seconds_since(start);
    if (out.timings.kernel <= 0) out.timings.kernel = out.timings.total;  // a host backend: its wall time, as BackendSampler's slabs
    out.timings.point_triangle_pairs = double(out.sampler.points_computed) * double(mesh.triangles().size());
    return out;
}

}  // namespace sdf

namespace sdf {

SparseBandField BoundSampler::sample_band_sparse(const Lattice& lattice, double width, BandChannels channels) const {
    require_band_width(width, "sparse band width");
    SampledField field = sample(lattice);
    if (field.sampler.band && field.sampler.band->width < width)
        throw std::invalid_argument("sparse band of width " + std::to_string(width) + ": sampler " + name() +
                                    " bands its fields at " + std::to_string(field.sampler.band->width) +
                                    ", narrower; sample with band_width 0 or >= the band's");
    apply_narrow_band(field, width);
    SparseBandField band = SparseBandField::sparsify(field, width, channels);
    if (band.sampler.band) band.sampler.band->how = "post-processed: the whole lattice sampled, then sparsified";
    return band;
}

}  // namespace sdf
