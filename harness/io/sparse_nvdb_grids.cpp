/// @file sparse_nvdb_grids.cpp
/// @brief The sparse band's NanoVDB grids (sparse_nvdb_grids.h): each grid planned and laid
/// out breadth first straight from the band's blocks (no intermediate tree), every node and
/// its statistics on every core. Built where NanoVDB's headers are found.
#include "harness/io/sparse_nvdb_grids.h"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <nanovdb/tools/GridChecksum.h>

#include "core/host_memory.h"
#include "core/parallel/parallel_for.h"
#include "harness/io/field_file.h"
#include "harness/io/volume_grids.h"

namespace sdf {
namespace {

using Leaf = nanovdb::NanoLeaf<float>;
using Lower = nanovdb::NanoLower<float>;
using Upper = nanovdb::NanoUpper<float>;
using Root = nanovdb::NanoRoot<float>;
using Tree = nanovdb::NanoTree<float>;
using Grid = nanovdb::NanoGrid<float>;
static_assert(Leaf::DIM == uint32_t(kBandBlockDim), "a band block is a NanoVDB leaf");

// A node's place in NanoVDB's breadth-first order, as one integer: its upper node's id (the
// cosets' upper nodes numbered coset by coset, each coset's in x, then y, then z order: the
// order of the root table that NanoVDB's builders keep sorted by origin), then the lower
// node's offset in its upper node and the leaf's in its lower node (x, then y, then z:
// NanoVDB's CoordToOffset). Sorting leaves by key gives the leaf array; key >> kLeafBits,
// the lower nodes'; key >> (kLeafBits + kLowerBits), the upper nodes'.
constexpr int kLeafBits = 3 * int(Lower::LOG2DIM);   // 12
constexpr int kLowerBits = 3 * int(Upper::LOG2DIM);  // 15
constexpr int kLeavesPerLower = 1 << Lower::LOG2DIM;  // per axis: 16
constexpr int kLowersPerUpper = 1 << Upper::LOG2DIM;  // per axis: 32
constexpr int kBlocksPerUpper = kLeavesPerLower * kLowersPerUpper;
constexpr int kMaxUpperBits = 64 - kLeafBits - kLowerBits;

struct NodeKeys {
    int cosets = 0;
    Int3 uppers[kMaxLatticeCosets]{};   // per axis
    uint64_t first_upper[kMaxLatticeCosets + 1]{};

    explicit NodeKeys(const BandBlockGrid& grid) : cosets(grid.cosets) {
        for (int c = 0; c < cosets; ++c) {
            const Int3 b = grid.coset[c].blocks;
            uppers[c] = {(b.x + kBlocksPerUpper - 1) / kBlocksPerUpper, (b.y + kBlocksPerUpper - 1) / kBlocksPerUpper,
                         (b.z + kBlocksPerUpper - 1) / kBlocksPerUpper};
            first_upper[c + 1] = first_upper[c] + uint64_t(uppers[c].x) * uint64_t(uppers[c].y) * uint64_t(uppers[c].z);
        }
        if (first_upper[cosets] >= (uint64_t(1) << kMaxUpperBits))
            throw std::length_error("a NanoVDB grid of " + std::to_string(first_upper[cosets]) + " upper nodes cannot be keyed");
    }
    uint64_t leaf_key(const BandBlockCoords& b) const {
        const Int3 u = {b.block.x / kBlocksPerUpper, b.block.y / kBlocksPerUpper, b.block.z / kBlocksPerUpper};
        const uint64_t upper = first_upper[b.coset] + (uint64_t(u.x) * uint64_t(uppers[b.coset].y) + uint64_t(u.y)) * uint64_t(uppers[b.coset].z) + uint64_t(u.z);
        const auto in = [](int block, int per, int count) { return uint64_t((block / per) % count); };
        const uint64_t lower = (in(b.block.x, kLeavesPerLower, kLowersPerUpper) << (2 * Upper::LOG2DIM)) |
                               (in(b.block.y, kLeavesPerLower, kLowersPerUpper) << Upper::LOG2DIM) |
                               in(b.block.z, kLeavesPerLower, kLowersPerUpper);
        const uint64_t leaf = (uint64_t(b.block.x % kLeavesPerLower) << (2 * Lower::LOG2DIM)) |
                              (uint64_t(b.block.y % kLeavesPerLower) << Lower::LOG2DIM) | uint64_t(b.block.z % kLeavesPerLower);
        return (((upper << kLowerBits) | lower) << kLeafBits) | leaf;
    }
    int coset_of_upper(uint64_t upper) const {
        int c = 0;
        while (c + 1 < cosets && upper >= first_upper[c + 1]) ++c;
        return c;
    }
    /// The first block (per axis) of an upper node.
    Int3 upper_block(uint64_t upper) const {
        const int c = coset_of_upper(upper);
        const uint64_t r = upper - first_upper[c];
        const uint64_t yz = uint64_t(uppers[c].y) * uint64_t(uppers[c].z);
        return {int(r / yz) * kBlocksPerUpper, int((r / uint64_t(uppers[c].z)) % uint64_t(uppers[c].y)) * kBlocksPerUpper,
                int(r % uint64_t(uppers[c].z)) * kBlocksPerUpper};
    }
    /// The first block of a lower node (key >> kLeafBits).
    Int3 lower_block(uint64_t lower) const {
        const Int3 u = upper_block(lower >> kLowerBits);
        const uint32_t o = uint32_t(lower & ((1u << kLowerBits) - 1));
        const uint32_t m = kLowersPerUpper - 1;
        return {u.x + int(o >> (2 * Upper::LOG2DIM)) * kLeavesPerLower, u.y + int((o >> Upper::LOG2DIM) & m) * kLeavesPerLower,
                u.z + int(o & m) * kLeavesPerLower};
    }
};

nanovdb::Coord voxel_origin(const Int3& block) {
    return nanovdb::Coord(block.x * kBandBlockDim, block.y * kBandBlockDim, block.z * kBandBlockDim);
}

/// Stable LSD radix sort of `keys` (below 2^bits), 16 bits a pass, carrying `payload`.
void radix_sort(std::vector<uint64_t>& keys, std::vector<int64_t>& payload, int bits) {
    constexpr int kDigit = 16;
    std::vector<uint64_t> k2(keys.size());
    std::vector<int64_t> p2(payload.size());
    std::vector<size_t> start(size_t(1) << kDigit);
    for (int shift = 0; shift < bits; shift += kDigit) {
        std::fill(start.begin(), start.end(), 0);
        for (uint64_t k : keys) ++start[(k >> shift) & 0xffff];
        size_t sum = 0;
        for (size_t& s : start) sum += std::exchange(s, sum);
        for (size_t i = 0; i < keys.size(); ++i) {
            const size_t at = start[(keys[i] >> shift) & 0xffff]++;
            k2[at] = keys[i];
            if (!payload.empty()) p2[at] = payload[i];
        }
        keys.swap(k2);
        payload.swap(p2);
    }
}

int bit_width(uint64_t v) { return v ? 64 - __builtin_clzll(v) : 0; }

/// NanoVDB's leaf offset of the block-local point `local` (ours runs x fastest, NanoVDB's z).
uint32_t leaf_offset(int local) {
    const Int3 o = BandLayout::local_offset(local);
    return uint32_t((o.x << (2 * kBandBlockLog2)) | (o.y << kBandBlockLog2) | o.z);
}

/// `count` (<= 16) bits of `words` from bit `at`.
uint32_t bits_at(const std::vector<uint64_t>& words, int64_t at, int count) {
    const size_t w = size_t(at >> 6);
    const int shift = int(at & 63);
    uint64_t v = words[w] >> shift;
    if (shift + count > 64 && w + 1 < words.size()) v |= words[w + 1] << (64 - shift);
    return uint32_t(v & ((uint64_t(1) << count) - 1));
}

/// The band's leaves (active blocks, then mixed blocks: index i < active.size() is
/// active[i], else mixed[i - active.size()]) in NanoVDB order, with their keys.
struct SortedLeaves {
    std::vector<uint64_t> keys;
    std::vector<int64_t> source;
};

SortedLeaves sort_leaves(const SparseBandField& band, const BandBlockGrid& blocks, const NodeKeys& nodes) {
    const size_t active = band.active.size(), count = active + band.mixed.size();
    SortedLeaves s;
    s.keys.resize(count);
    s.source.resize(count);
    parallel_for(int64_t(count), 1 << 14, 0, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1; ++i) {
            const int64_t id = size_t(i) < active ? band.active[size_t(i)] : band.mixed[size_t(i) - active];
            s.keys[size_t(i)] = nodes.leaf_key(blocks.block_coords(id));
            s.source[size_t(i)] = i;
        }
    });
    radix_sort(s.keys, s.source, bit_width(nodes.first_upper[nodes.cosets]) + kLowerBits + kLeafBits);
    return s;
}

/// The lower nodes holding an inside tile (a block whose bit in inside_tiles is set; blocks
/// that are leaves are dropped later), sorted, each once.
std::vector<uint64_t> inside_tile_lowers(const SparseBandField& band, const BandBlockGrid& blocks, const NodeKeys& nodes) {
    const int64_t words = int64_t(band.inside_tiles.size());
    const int64_t chunk = 1 << 12;
    std::vector<std::vector<uint64_t>> found(size_t((words + chunk - 1) / chunk));
    parallel_for(int64_t(found.size()), 1, 0, [&](int64_t c0, int64_t c1) {
        for (int64_t c = c0; c < c1; ++c) {
            std::vector<uint64_t>& out = found[size_t(c)];
            for (int64_t w = c * chunk; w < std::min(words, (c + 1) * chunk); ++w) {
                for (uint64_t bits = band.inside_tiles[size_t(w)]; bits; bits &= bits - 1) {
                    const int64_t id = w * 64 + __builtin_ctzll(bits);
                    if (id >= blocks.block_count) break;
                    const uint64_t lower = nodes.leaf_key(blocks.block_coords(id)) >> kLeafBits;
                    if (out.empty() || out.back() != lower) out.push_back(lower);
                }
            }
        }
    });
    std::vector<uint64_t> lowers;
    for (const std::vector<uint64_t>& f : found) lowers.insert(lowers.end(), f.begin(), f.end());
    std::vector<int64_t> none;
    radix_sort(lowers, none, bit_width(nodes.first_upper[nodes.cosets]) + kLowerBits);
    lowers.erase(std::unique(lowers.begin(), lowers.end()), lowers.end());
    return lowers;
}

/// [begin, end) of the sorted `keys` whose key >> shift is `prefix`.
std::pair<size_t, size_t> run_of(const std::vector<uint64_t>& keys, uint64_t prefix, int shift) {
    const auto lo = std::lower_bound(keys.begin(), keys.end(), prefix << shift);
    const auto hi = std::lower_bound(lo, keys.end(), (prefix + 1) << shift);
    return {size_t(lo - keys.begin()), size_t(hi - keys.begin())};
}

/// A filled leaf's and an internal node's statistics, as tools/GridStats.h sets them.
template <typename DataT>
void set_stats(DataT& data, const nanovdb::tools::Stats<float>& s) {
    data.setMin(s.min());
    data.setMax(s.max());
    data.setAvg(s.avg());
    data.setDev(s.std());
}

/// A filled leaf's box (LeafNode::updateBBox) and statistics; its flags as GridStats leaves
/// them for a level set without a rendering delta (bit 0 clear).
NanoNodeStats leaf_stats(Leaf& leaf) {
    NanoNodeStats local;
    if (leaf.updateBBox()) {
        auto& data = *leaf.data();
        local.bbox[0] = local.bbox[1] = data.mBBoxMin;
        local.bbox[1] += nanovdb::Coord(data.mBBoxDif[0], data.mBBoxDif[1], data.mBBoxDif[2]);
        for (auto it = leaf.cbeginValueOn(); it; ++it) local.stats.add(*it);
        set_stats(data, local.stats);
        data.mFlags &= ~uint8_t(1);
    }
    return local;
}

/// An internal node's box, flags and statistics from its children's (GridStats::process).
template <typename DataT>
void set_node_stats(DataT& data, const NanoNodeStats& total) {
    data.mBBox = total.bbox;
    if (total.bbox.empty()) {
        data.mFlags |= uint64_t(1);   // nothing to render
        data.mFlags &= ~uint64_t(2);  // no active value
    } else {
        data.mFlags |= uint64_t(2);
        set_stats(data, total.stats);
        data.mFlags &= ~uint64_t(1);
    }
}

void fill_leaf(const SparseBandField& band, const BandBlockGrid& blocks, int64_t i, Leaf& leaf, int64_t& on) {
    const size_t active = band.active.size();
    const bool is_active = size_t(i) < active;
    const int64_t id = is_active ? band.active[size_t(i)] : band.mixed[size_t(i) - active];
    const BandBlockCoords b = blocks.block_coords(id);
    const Int3 points = blocks.block_points(b);
    const bool whole = BandBlockGrid::whole(points);
    const float w = float(band.width);
    auto& data = *leaf.data();
    if (Leaf::DataType::padding() > 0) std::memset(static_cast<void*>(&data), 0, Leaf::DataType::memUsage());
    data.mBBoxMin = voxel_origin(b.block);
    data.mBBoxDif[0] = data.mBBoxDif[1] = data.mBBoxDif[2] = 0;
    data.mFlags = 0;
    data.mMinimum = data.mMaximum = 0.0f;
    data.mAverage = data.mStdDevi = 0.0f;
    data.mValueMask.setOff();
    std::fill(data.mValues, data.mValues + Leaf::SIZE, w);  // padding: the background +W
    if (!is_active) {  // a mixed block: inactive voxels, each on its side
        const BandSignMask& inside = band.mixed_inside[size_t(i) - active];
        for (int local = 0; local < kBandBlockPoints; ++local)
            if ((whole || BandBlockGrid::within(points, local)) && mask_bit(inside, local)) data.mValues[leaf_offset(local)] = -w;
        return;
    }
    band.distance.visit([&](const auto* values) {  // double, or float32 (a band held for float32 outputs)
        const auto* distance = values + size_t(i) * kBandBlockPoints;
        for (int local = 0; local < kBandBlockPoints; ++local) {
            if (!whole && !BandBlockGrid::within(points, local)) continue;
            const uint32_t n = leaf_offset(local);
            data.mValues[n] = float(distance[local]);  // a band point's value, else +-W, its side
            if (band.in_band(size_t(i), local)) {
                data.mValueMask.setOn(n);
                ++on;
            }
        }
    });
}

}  // namespace

void check_band_for_nanovdb(const SparseBandField& band, const std::string& what) {
    if (!(band.width > 0)) throw std::invalid_argument(what + ": a sparse band needs a width W > 0");
    // The distances (float32 or double: a .nvdb stores float32) and masks match the active blocks.
    band.require_channels({false, false, BandDistanceType::Float32}, what);
    require_representable_band(band.width, FieldDtype::Float32, what + ": the band's width (a .nvdb stores float32)");
    const BandBlockGrid blocks = BandBlockGrid::of(band.lattice);
    const int64_t count = band.layout().block_count();
    if (blocks.block_count != count || blocks.cosets != band.layout().cosets())
        throw std::invalid_argument(what + ": the band's lattice is not the one its blocks were laid out for");
    if (band.inside_tiles.size() != size_t((count + 63) / 64))
        throw std::invalid_argument(what + ": the band's tile signs hold " + std::to_string(band.inside_tiles.size()) +
                                    " words for " + std::to_string(count) + " blocks");
    if (band.mixed_inside.size() != band.mixed.size())
        throw std::invalid_argument(what + ": the band's " + std::to_string(band.mixed.size()) + " mixed blocks have " +
                                    std::to_string(band.mixed_inside.size()) + " sign masks");
    for (const std::vector<int64_t>* ids : {&band.active, &band.mixed})
        for (size_t i = 0; i < ids->size(); ++i)
            if ((*ids)[i] < 0 || (*ids)[i] >= count || (i > 0 && (*ids)[i] <= (*ids)[i - 1]))
                throw std::invalid_argument(what + ": the band's block ids must ascend within [0, " + std::to_string(count) +
                                            "); got " + std::to_string((*ids)[i]) + " at " + std::to_string(i));
}

NanoNodeStats& NanoNodeStats::add(const NanoNodeStats& other) {
    stats.add(other.stats);
    bbox[0].minComponent(other.bbox[0]);
    bbox[1].maxComponent(other.bbox[1]);
    return *this;
}

/// The sorted node lists and the keys (see NodeKeys).
struct SparseNanoPlan::Nodes {
    BandBlockGrid blocks;
    NodeKeys keys;
    float w;
    SortedLeaves leaves;
    std::vector<uint64_t> lowers, uppers;
};

SparseNanoPlan::~SparseNanoPlan() = default;

SparseNanoPlan::SparseNanoPlan(const SparseBandField& band, const std::string& what) : band_(band) {
    check_band_for_nanovdb(band, what);
    const BandBlockGrid blocks = BandBlockGrid::of(band.lattice);
    Nodes lists{blocks, NodeKeys(blocks), float(band.width), {}, {}, {}};
    const std::vector<VolumeGrid> parts = volume_grids(band.lattice);
    if (int(parts.size()) != lists.blocks.cosets)
        throw std::invalid_argument(what + ": a BCC lattice with one point along an axis has no secondary grid, and a "
                                           ".nvdb of it would name one; expected at least 2 points per axis");
    for (int c = 0; c < lists.blocks.cosets; ++c)  // NanoVDB's index coordinates are 32-bit (a block's origin is 8 its index)
        for (int k = 0; k < 3; ++k)
            if (int64_t(lists.blocks.coset[c].blocks[k]) * kBandBlockDim > int64_t(INT32_MAX))
                throw std::length_error("a NanoVDB grid holds at most 2^31 - 1 voxels per axis; this lattice has " +
                                        std::to_string(lists.blocks.coset[c].points[k]) + " points along an axis");
    // The leaves sorted into NanoVDB's order; the lower nodes of the leaves and of the
    // inside tiles; their upper nodes.
    lists.leaves = sort_leaves(band, lists.blocks, lists.keys);
    if (std::adjacent_find(lists.leaves.keys.begin(), lists.leaves.keys.end()) != lists.leaves.keys.end())
        throw std::logic_error("a sparse band lists a block twice (active and mixed): a NanoVDB leaf cannot be two");
    lists.lowers = inside_tile_lowers(band, lists.blocks, lists.keys);
    std::vector<uint64_t> of_leaves, merged;
    for (uint64_t k : lists.leaves.keys)
        if (of_leaves.empty() || of_leaves.back() != k >> kLeafBits) of_leaves.push_back(k >> kLeafBits);
    merged.reserve(lists.lowers.size() + of_leaves.size());
    std::set_union(lists.lowers.begin(), lists.lowers.end(), of_leaves.begin(), of_leaves.end(), std::back_inserter(merged));
    lists.lowers.swap(merged);
    for (uint64_t k : lists.lowers)
        if (lists.uppers.empty() || lists.uppers.back() != k >> kLowerBits) lists.uppers.push_back(k >> kLowerBits);

    for (int c = 0; c < lists.blocks.cosets; ++c) {
        // This coset's runs of the three sorted node lists.
        const uint64_t u0 = lists.keys.first_upper[c], u1 = lists.keys.first_upper[c + 1];
        const auto range = [](const std::vector<uint64_t>& keys, uint64_t lo, uint64_t hi) {
            return std::pair<size_t, size_t>(size_t(std::lower_bound(keys.begin(), keys.end(), lo) - keys.begin()),
                                             size_t(std::lower_bound(keys.begin(), keys.end(), hi) - keys.begin()));
        };
        GridPlan g;
        std::tie(g.upper_begin, g.upper_end) = range(lists.uppers, u0, u1);
        std::tie(g.lower_begin, g.lower_end) = range(lists.lowers, u0 << kLowerBits, u1 << kLowerBits);
        std::tie(g.leaf_begin, g.leaf_end) = range(lists.leaves.keys, u0 << (kLowerBits + kLeafBits), u1 << (kLowerBits + kLeafBits));
        g.tree_at = Grid::memUsage();
        g.root_at = g.tree_at + Tree::memUsage();
        g.upper_at = g.root_at + Root::memUsage(uint32_t(g.uppers()));
        g.lower_at = g.upper_at + Upper::memUsage() * g.uppers();
        g.leaf_at = g.lower_at + Lower::memUsage() * g.lowers();
        g.size = g.leaf_at + Leaf::DataType::memUsage() * g.leaves();
        if (g.leaves() > UINT32_MAX || g.lowers() > UINT32_MAX)  // TreeData's node counts are 32-bit
            throw std::length_error("a NanoVDB grid holds at most 2^32 - 1 nodes of a level; this band has " +
                                    std::to_string(g.leaves()) + " leaves in one grid");
        const VolumeGrid& part = parts[size_t(c)];
        g.name = part.part.empty() ? "distance" : "distance_" + part.part;
        g.map.set(part.spacing, nanovdb::Vec3d(part.origin.x, part.origin.y, part.origin.z), 1.0);  // build::Grid::setTransform's
        grids_.push_back(g);
    }
    nodes_ = std::make_unique<const Nodes>(std::move(lists));
}

std::pair<size_t, size_t> SparseNanoPlan::leaves_of_lower(int c, size_t n) const {
    const Nodes& lists = *nodes_;
    const GridPlan& g = grids_[size_t(c)];
    const auto [l0, l1] = run_of(lists.leaves.keys, lists.lowers[g.lower_begin + n], kLeafBits);
    return {l0 - g.leaf_begin, l1 - g.leaf_begin};
}

NanoNodeStats SparseNanoPlan::build_lower(int c, size_t n, char* top, Leaf* leaves, int64_t& on, int64_t& inside) const {
    const Nodes& lists = *nodes_;
    const GridPlan& g = grids_[size_t(c)];
    const uint64_t key = lists.lowers[g.lower_begin + n];
    const uint64_t node_at = g.lower_at + Lower::memUsage() * n;
    auto& data = *reinterpret_cast<Lower*>(top + node_at)->data();
    std::memset(static_cast<void*>(&data), 0, Lower::memUsage());
    const Int3 first = lists.keys.lower_block(key);
    data.mBBox[0] = voxel_origin(first);
    for (uint32_t t = 0; t < Lower::SIZE; ++t) data.mTable[t].value = lists.w;
    const BandCoset& s = lists.blocks.coset[c];
    const int nx = std::min(kLeavesPerLower, s.blocks.x - first.x);
    for (int z = first.z; z < std::min(first.z + kLeavesPerLower, s.blocks.z); ++z)
        for (int y = first.y; y < std::min(first.y + kLeavesPerLower, s.blocks.y); ++y) {
            const int64_t id = s.first_block + first.x + int64_t(s.blocks.x) * (y + int64_t(s.blocks.y) * z);
            for (uint32_t bits = bits_at(band_.inside_tiles, id, nx); bits; bits &= bits - 1) {
                const uint32_t x = uint32_t(__builtin_ctz(bits));
                data.mTable[(x << (2 * Lower::LOG2DIM)) | (uint32_t(y - first.y) << Lower::LOG2DIM) | uint32_t(z - first.z)].value = -lists.w;
                ++inside;
            }
        }
    NanoNodeStats total;
    const auto [l0, l1] = run_of(lists.leaves.keys, key, kLeafBits);
    for (size_t l = l0; l < l1; ++l) {
        const uint32_t t = uint32_t(lists.leaves.keys[l] & ((1u << kLeafBits) - 1));
        inside -= data.mTable[t].value == -lists.w;  // a leaf, not a tile
        data.mChildMask.setOn(t);
        data.mTable[t].child = int64_t(g.leaf_at + Leaf::DataType::memUsage() * (l - g.leaf_begin)) - int64_t(node_at);
        Leaf& leaf = leaves[l - l0];
        fill_leaf(band_, lists.blocks, lists.leaves.source[l], leaf, on);
        total.add(leaf_stats(leaf));
    }
    set_node_stats(data, total);
    return total;
}

void SparseNanoPlan::finish(int c, char* top, const std::vector<NanoNodeStats>& lower_stats, int64_t voxels) const {
    const Nodes& lists = *nodes_;
    const GridPlan& g = grids_[size_t(c)];
    std::vector<NanoNodeStats> upper_stats(g.uppers());
    parallel_for(int64_t(g.uppers()), 1, 0, [&](int64_t n0, int64_t n1) {
        for (int64_t n = n0; n < n1; ++n) {
            const uint64_t key = lists.uppers[g.upper_begin + size_t(n)];
            const uint64_t node_at = g.upper_at + Upper::memUsage() * uint64_t(n);
            auto& data = *reinterpret_cast<Upper*>(top + node_at)->data();
            std::memset(static_cast<void*>(&data), 0, Upper::memUsage());
            data.mBBox[0] = voxel_origin(lists.keys.upper_block(key));
            for (uint32_t t = 0; t < Upper::SIZE; ++t) data.mTable[t].value = lists.w;
            NanoNodeStats total;
            const auto [l0, l1] = run_of(lists.lowers, key, kLowerBits);
            for (size_t l = l0; l < l1; ++l) {
                const uint32_t t = uint32_t(lists.lowers[l] & ((1u << kLowerBits) - 1));
                data.mChildMask.setOn(t);
                data.mTable[t].child = int64_t(g.lower_at + Lower::memUsage() * (l - g.lower_begin)) - int64_t(node_at);
                total.add(lower_stats[l - g.lower_begin]);
            }
            set_node_stats(data, total);
            upper_stats[size_t(n)] = total;
        }
    });

    // The root: one child tile per upper node, in order.
    auto& root = *reinterpret_cast<Root*>(top + g.root_at)->data();
    std::memset(static_cast<void*>(&root), 0, Root::memUsage(uint32_t(g.uppers())));
    root.mTableSize = uint32_t(g.uppers());
    root.mMinimum = root.mMaximum = root.mBackground = lists.w;
    root.mBBox = nanovdb::CoordBBox();
    NanoNodeStats total;
    for (uint64_t n = 0; n < g.uppers(); ++n) {
        auto& tile = *root.tile(uint32_t(n));
        tile.setValue(voxel_origin(lists.keys.upper_block(lists.uppers[g.upper_begin + n])), false, 0.0f);  // the key; then the child
        tile.child = int64_t(g.upper_at + Upper::memUsage() * n) - int64_t(g.root_at);
        total.add(upper_stats[n]);
    }
    if (g.uppers() > 0) {  // else min = max = background, average and deviation 0, an empty box
        set_stats(root, total.stats);
        root.mBBox = total.bbox;
    }

    auto& tree = *reinterpret_cast<Tree*>(top + g.tree_at)->data();
    const auto offset = [&](uint64_t count, uint64_t at) { return count ? int64_t(at) - int64_t(g.tree_at) : int64_t(0); };
    tree.mNodeOffset[0] = offset(g.leaves(), g.leaf_at);
    tree.mNodeOffset[1] = offset(g.lowers(), g.lower_at);
    tree.mNodeOffset[2] = offset(g.uppers(), g.upper_at);
    tree.mNodeOffset[3] = int64_t(g.root_at - g.tree_at);
    tree.mNodeCount[0] = uint32_t(g.leaves());
    tree.mNodeCount[1] = uint32_t(g.lowers());
    tree.mNodeCount[2] = uint32_t(g.uppers());
    tree.mTileCount[0] = tree.mTileCount[1] = tree.mTileCount[2] = 0;  // every tile inactive
    tree.mVoxelCount = uint64_t(voxels);

    Grid& grid = *reinterpret_cast<Grid*>(top);
    auto& data = *grid.data();
    data.init({nanovdb::GridFlags::IsBreadthFirst}, g.size, g.map, nanovdb::GridType::Float, nanovdb::GridClass::LevelSet);
    std::memset(data.mGridName, 0, nanovdb::GridData::MaxNameSize);
    std::strncpy(data.mGridName, g.name.c_str(), nanovdb::GridData::MaxNameSize - 1);
    // The world box and flags, as GridStats::process(Grid&).
    if (root.mBBox.empty()) {
        data.mWorldBBox = nanovdb::Vec3dBBox();
        data.setBBoxOn(false);
    } else {
        data.mWorldBBox = nanovdb::CoordBBox(root.mBBox[0], root.mBBox[1].offsetBy(1)).transform(grid.map());
        data.setBBoxOn(true);
    }
    data.setMinMaxOn(true);
    data.setAverageOn(true);
    data.setStdDeviationOn(true);
    nanovdb::tools::updateChecksum(&grid, nanovdb::CheckMode::Default);  // the head: grid and tree
}

std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> sparse_band_nanogrids(const SparseBandField& band, SparseNvdbCounts* counts_out) {
    const SparseNanoPlan plan(band, "the NanoVDB grids");
    SparseNvdbCounts counts;
    std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
    for (int c = 0; c < plan.grids(); ++c) {
        const SparseNanoPlan::GridPlan& g = plan.grid(c);
        require_host_bytes(g.size, "the NanoVDB grid of " + std::to_string(g.leaves()) + " leaves");
        nanovdb::HostBuffer buffer = nanovdb::HostBuffer::create(g.size);
        char* top = static_cast<char*>(buffer.data());
        advise_huge_pages(top, g.size);  // untouched yet: the leaves' fill is the first touch
        Leaf* leaves = reinterpret_cast<Leaf*>(top + g.leaf_at);
        std::vector<NanoNodeStats> lower_stats(g.lowers());
        std::atomic<int64_t> voxels{0}, inside_tiles{0};
        parallel_for(int64_t(g.lowers()), 1, 0, [&](int64_t n0, int64_t n1) {
            int64_t on = 0, inside = 0;
            for (int64_t n = n0; n < n1; ++n)
                lower_stats[size_t(n)] = plan.build_lower(c, size_t(n), top, leaves + plan.leaves_of_lower(c, size_t(n)).first, on, inside);
            voxels += on;
            inside_tiles += inside;
        });
        plan.finish(c, top, lower_stats, voxels.load());
        counts.leaves += int64_t(g.leaves());
        counts.active_voxels += voxels.load();
        counts.inside_tiles += inside_tiles.load();
        counts.bytes += int64_t(g.size);
        handles.emplace_back(std::move(buffer));
    }
    if (counts_out) *counts_out = counts;
    return handles;
}

}  // namespace sdf
