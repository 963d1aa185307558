/// @file sparse_nvdb_file.cpp
/// @brief The sparse band's NanoVDB writer (sparse_nvdb_file.h, sparse_nvdb_grids.h): each
/// grid laid out in place, breadth first, straight from the band's blocks (no intermediate
/// tree, no second copy of the leaves), then written to a temporary, synced and placed
/// (write_through_temporary).
#include "harness/io/sparse_nvdb_file.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "core/host_memory.h"
#include "core/parallel/parallel_for.h"
#include "harness/io/field_file.h"
#include "harness/io/volume_grids.h"

#if SDF_HAVE_NANOVDB
#include <nanovdb/NanoVDB.h>
#include <nanovdb/io/IO.h>
#include <nanovdb/tools/GridChecksum.h>
#include <nanovdb/tools/GridStats.h>

#include "harness/io/sparse_nvdb_grids.h"
#endif

namespace sdf {

#if SDF_HAVE_NANOVDB
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
        if (first_upper[cosets] > (uint64_t(1) << kMaxUpperBits))
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

/// A node's active bounding box and the statistics of its active values: GridStats's own
/// (tools/GridStats.h, StatsMode::All), which NanoVDB's conversion computes on one thread;
/// here each lower node's leaves and each upper node's lower nodes on every core, in the order
/// GridStats visits them, so that every float written is the one it writes.
struct NodeStats {
    nanovdb::tools::Stats<float> stats;
    nanovdb::CoordBBox bbox;
    void add(const NodeStats& other) {
        stats.add(other.stats);
        bbox[0].minComponent(other.bbox[0]);
        bbox[1].maxComponent(other.bbox[1]);
    }
};

template <typename DataT>
void set_stats(DataT& data, const nanovdb::tools::Stats<float>& s) {
    data.setMin(s.min());
    data.setMax(s.max());
    data.setAvg(s.avg());
    data.setDev(s.std());
}

/// A filled leaf's box (LeafNode::updateBBox) and statistics; its flags as GridStats leaves
/// them for a level set without a rendering delta (bit 0 clear).
NodeStats leaf_stats(Leaf& leaf) {
    NodeStats local;
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
void set_node_stats(DataT& data, const NodeStats& total) {
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
    const double* distance = band.distance.data() + size_t(i) * kBandBlockPoints;
    for (int local = 0; local < kBandBlockPoints; ++local) {
        if (!whole && !BandBlockGrid::within(points, local)) continue;
        const uint32_t n = leaf_offset(local);
        data.mValues[n] = float(distance[local]);  // a band point's value, else +-W, its side
        if (band.in_band(size_t(i), local)) {
            data.mValueMask.setOn(n);
            ++on;
        }
    }
}

}  // namespace

std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> sparse_band_nanogrids(const SparseBandField& band, SparseNvdbCounts* counts_out) {
    const BandLayout& layout = band.layout();
    const BandBlockGrid blocks = BandBlockGrid::of(band.lattice);
    const std::vector<VolumeGrid> parts = volume_grids(band.lattice);
    if (int(parts.size()) != layout.cosets() || blocks.cosets != layout.cosets())
        throw std::logic_error("the band's cosets are not the lattice's grids");
    const float w = float(band.width);
    const NodeKeys nodes(blocks);

    // The nodes: leaves sorted into NanoVDB's order; the lower nodes of the leaves and of the
    // inside tiles; their upper nodes.
    const SortedLeaves leaves = sort_leaves(band, blocks, nodes);
    std::vector<uint64_t> lowers = inside_tile_lowers(band, blocks, nodes);
    {
        std::vector<uint64_t> of_leaves;
        for (uint64_t k : leaves.keys)
            if (of_leaves.empty() || of_leaves.back() != k >> kLeafBits) of_leaves.push_back(k >> kLeafBits);
        std::vector<uint64_t> merged;
        merged.reserve(lowers.size() + of_leaves.size());
        std::set_union(lowers.begin(), lowers.end(), of_leaves.begin(), of_leaves.end(), std::back_inserter(merged));
        lowers.swap(merged);
    }
    std::vector<uint64_t> uppers;
    for (uint64_t k : lowers)
        if (uppers.empty() || uppers.back() != k >> kLowerBits) uppers.push_back(k >> kLowerBits);

    SparseNvdbCounts counts;
    std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
    for (int c = 0; c < layout.cosets(); ++c) {
        // This coset's runs of the three sorted node lists.
        const uint64_t u0 = nodes.first_upper[c], u1 = nodes.first_upper[c + 1];
        const auto range = [](const std::vector<uint64_t>& keys, uint64_t lo, uint64_t hi) {
            return std::pair<size_t, size_t>(size_t(std::lower_bound(keys.begin(), keys.end(), lo) - keys.begin()),
                                             size_t(std::lower_bound(keys.begin(), keys.end(), hi) - keys.begin()));
        };
        const auto [upper_begin, upper_end] = range(uppers, u0, u1);
        const auto [lower_begin, lower_end] = range(lowers, u0 << kLowerBits, u1 << kLowerBits);
        const auto [leaf_begin, leaf_end] = range(leaves.keys, u0 << (kLowerBits + kLeafBits), u1 << (kLowerBits + kLeafBits));
        const uint64_t upper_count = upper_end - upper_begin, lower_count = lower_end - lower_begin, leaf_count = leaf_end - leaf_begin;

        // The breadth-first layout NanoVDB's CreateNanoGrid gives (no blind data).
        const uint64_t tree_at = Grid::memUsage(), root_at = tree_at + Tree::memUsage();
        const uint64_t upper_at = root_at + Root::memUsage(uint32_t(upper_count));
        const uint64_t lower_at = upper_at + Upper::memUsage() * upper_count;
        const uint64_t leaf_at = lower_at + Lower::memUsage() * lower_count;
        const uint64_t size = leaf_at + Leaf::DataType::memUsage() * leaf_count;
        require_host_bytes(size, "the NanoVDB grid of " + std::to_string(leaf_count) + " leaves");
        nanovdb::HostBuffer buffer = nanovdb::HostBuffer::create(size);
        char* base = static_cast<char*>(buffer.data());
        advise_huge_pages(base, size);  // untouched yet: the leaves' fill below is the first touch
        Leaf* leaf_nodes = reinterpret_cast<Leaf*>(base + leaf_at);
        Lower* lower_nodes = reinterpret_cast<Lower*>(base + lower_at);
        Upper* upper_nodes = reinterpret_cast<Upper*>(base + upper_at);
        Root* root = reinterpret_cast<Root*>(base + root_at);

        // Lower nodes, each with its leaves, on every core (the leaves' fill is the first
        // touch of most of the grid's memory): +W tiles (the background), -W where a block is
        // an inside tile, the leaves as children; then, as tools/GridStats.h computes them
        // (StatsMode::All, in its order: each node's children in offset order), each leaf's
        // and lower node's active bounding box and statistics.
        std::vector<NodeStats> lower_stats(lower_count);
        std::atomic<int64_t> voxels{0}, inside_tiles{0};
        parallel_for(int64_t(lower_count), 1, 0, [&](int64_t n0, int64_t n1) {
            int64_t on = 0, inside = 0;
            for (int64_t n = n0; n < n1; ++n) {
                const uint64_t key = lowers[lower_begin + size_t(n)];
                Lower& lower = lower_nodes[n];
                auto& data = *lower.data();
                std::memset(static_cast<void*>(&data), 0, Lower::memUsage());
                const Int3 first = nodes.lower_block(key);
                data.mBBox[0] = voxel_origin(first);
                for (uint32_t t = 0; t < Lower::SIZE; ++t) data.mTable[t].value = w;
                const BandCoset& s = blocks.coset[nodes.coset_of_upper(key >> kLowerBits)];
                const int nx = std::min(kLeavesPerLower, s.blocks.x - first.x);
                for (int z = first.z; z < std::min(first.z + kLeavesPerLower, s.blocks.z); ++z)
                    for (int y = first.y; y < std::min(first.y + kLeavesPerLower, s.blocks.y); ++y) {
                        const int64_t id = s.first_block + first.x + int64_t(s.blocks.x) * (y + int64_t(s.blocks.y) * z);
                        for (uint32_t bits = bits_at(band.inside_tiles, id, nx); bits; bits &= bits - 1) {
                            const uint32_t x = uint32_t(__builtin_ctz(bits));
                            data.mTable[(x << (2 * Lower::LOG2DIM)) | (uint32_t(y - first.y) << Lower::LOG2DIM) | uint32_t(z - first.z)].value = -w;
                            ++inside;
                        }
                    }
                NodeStats total;
                const auto [l0, l1] = run_of(leaves.keys, key, kLeafBits);
                for (size_t l = l0; l < l1; ++l) {
                    const uint32_t t = uint32_t(leaves.keys[l] & ((1u << kLeafBits) - 1));
                    inside -= data.mTable[t].value == -w;  // a leaf, not a tile
                    data.mChildMask.setOn(t);
                    Leaf& leaf = leaf_nodes[l - leaf_begin];
                    data.setChild(t, &leaf);
                    fill_leaf(band, blocks, leaves.source[l], leaf, on);
                    total.add(leaf_stats(leaf));
                }
                set_node_stats(data, total);
                lower_stats[size_t(n)] = total;
            }
            voxels += on;
            inside_tiles += inside;
        });

        // Upper nodes: +W tiles and their lower nodes as children.
        std::vector<NodeStats> upper_stats(upper_count);
        parallel_for(int64_t(upper_count), 1, 0, [&](int64_t n0, int64_t n1) {
            for (int64_t n = n0; n < n1; ++n) {
                const uint64_t key = uppers[upper_begin + size_t(n)];
                auto& data = *upper_nodes[n].data();
                std::memset(static_cast<void*>(&data), 0, Upper::memUsage());
                data.mBBox[0] = voxel_origin(nodes.upper_block(key));
                for (uint32_t t = 0; t < Upper::SIZE; ++t) data.mTable[t].value = w;
                NodeStats total;
                const auto [l0, l1] = run_of(lowers, key, kLowerBits);
                for (size_t l = l0; l < l1; ++l) {
                    const uint32_t t = uint32_t(lowers[l] & ((1u << kLowerBits) - 1));
                    data.mChildMask.setOn(t);
                    data.setChild(t, &lower_nodes[l - lower_begin]);
                    total.add(lower_stats[l - lower_begin]);
                }
                set_node_stats(data, total);
                upper_stats[size_t(n)] = total;
            }
        });

        // The root: one child tile per upper node, in order; the tree; the grid.
        auto& root_data = *root->data();
        std::memset(static_cast<void*>(&root_data), 0, Root::memUsage(uint32_t(upper_count)));
        root_data.mTableSize = uint32_t(upper_count);
        root_data.mMinimum = root_data.mMaximum = root_data.mBackground = w;
        root_data.mBBox = nanovdb::CoordBBox();
        NodeStats total;
        for (uint64_t n = 0; n < upper_count; ++n) {
            root_data.tile(uint32_t(n))->setChild(voxel_origin(nodes.upper_block(uppers[upper_begin + n])), &upper_nodes[n], &root_data);
            total.add(upper_stats[n]);
        }
        if (upper_count > 0) {  // else min = max = background, average and deviation 0, an empty box
            set_stats(root_data, total.stats);
            root_data.mBBox = total.bbox;
        }
        auto& tree = *reinterpret_cast<Tree*>(base + tree_at)->data();
        tree.setRoot(root);
        tree.setFirstNode(upper_count ? &upper_nodes[0] : static_cast<Upper*>(nullptr));
        tree.setFirstNode(lower_count ? &lower_nodes[0] : static_cast<Lower*>(nullptr));
        tree.setFirstNode(leaf_count ? &leaf_nodes[0] : static_cast<Leaf*>(nullptr));
        tree.mNodeCount[0] = uint32_t(leaf_count);
        tree.mNodeCount[1] = uint32_t(lower_count);
        tree.mNodeCount[2] = uint32_t(upper_count);
        tree.mTileCount[0] = tree.mTileCount[1] = tree.mTileCount[2] = 0;  // every tile inactive
        tree.mVoxelCount = uint64_t(voxels.load());

        const VolumeGrid& part = parts[size_t(c)];
        const std::string name = part.part.empty() ? "distance" : "distance_" + part.part;
        Grid& grid = *reinterpret_cast<Grid*>(base);
        nanovdb::Map map;
        map.set(part.spacing, nanovdb::Vec3d(part.origin.x, part.origin.y, part.origin.z), 1.0);
        auto& grid_data = *grid.data();
        grid_data.init({nanovdb::GridFlags::IsBreadthFirst}, size, map, nanovdb::GridType::Float, nanovdb::GridClass::LevelSet);
        std::memset(grid_data.mGridName, 0, nanovdb::GridData::MaxNameSize);
        std::strncpy(grid_data.mGridName, name.c_str(), nanovdb::GridData::MaxNameSize - 1);
        // The grid's world box and flags, as GridStats::process(Grid&).
        if (root_data.mBBox.empty()) {
            grid_data.mWorldBBox = nanovdb::Vec3dBBox();
            grid_data.setBBoxOn(false);
        } else {
            grid_data.mWorldBBox = nanovdb::CoordBBox(root_data.mBBox[0], root_data.mBBox[1].offsetBy(1)).transform(grid.map());
            grid_data.setBBoxOn(true);
        }
        grid_data.setMinMaxOn(true);
        grid_data.setAverageOn(true);
        grid_data.setStdDeviationOn(true);
        nanovdb::tools::updateChecksum(&grid, nanovdb::CheckMode::Default);

        counts.leaves += int64_t(leaf_count);
        counts.active_voxels += voxels.load();
        counts.inside_tiles += inside_tiles.load();
        counts.bytes += int64_t(size);
        handles.emplace_back(std::move(buffer));
    }
    if (counts_out) *counts_out = counts;
    return handles;
}

namespace {

// path: the temporary written; target: the name the messages give.
void write_grids(const SparseBandField& band, const std::string& path, const std::string& target, SparseNvdbCounts& counts) {
    const std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles = sparse_band_nanogrids(band, &counts);
    // NanoVDB's file-name overload neither checks its stream nor reports a short write: a full
    // disk would be placed as a whole file. Our own stream, checked after closing, does not.
    std::ofstream os(path, std::ios::binary | std::ios::trunc);
    if (!os) throw std::runtime_error(target + ": cannot open a file beside it for writing");
    nanovdb::io::writeGrids(os, handles);
    os.close();
    if (!os) throw std::runtime_error(target + ": writing the NanoVDB grids failed (disk full?)");
}

}  // namespace

bool nanovdb_available() { return true; }

SparseNvdbCounts write_sparse_band_nvdb(const SparseBandField& band, const std::string& path, Overwrite overwrite) {
    if (!(band.width > 0)) throw std::invalid_argument(path + ": a sparse band needs a width W > 0");
    band.require_channels({false, false}, path + ": the distance grids");  // the arrays match the active blocks
    require_representable_band(band.width, FieldDtype::Float32, path + ": the band's width (a .nvdb stores float32)");
    SparseNvdbCounts counts;
    write_through_temporary(path, overwrite,
                            [&](const std::string& temporary) { write_grids(band, temporary, path, counts); });
    return counts;
}

#else

bool nanovdb_available() { return false; }

SparseNvdbCounts write_sparse_band_nvdb(const SparseBandField&, const std::string& path, Overwrite) {
    throw std::runtime_error(path + ": this build has no NanoVDB support (its headers were not found at configure time: "
                                    "set SDF_NANOVDB_DIR to the folder holding nanovdb/NanoVDB.h)");
}

#endif

}  // namespace sdf
