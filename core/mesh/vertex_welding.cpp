#include "core/mesh/vertex_welding.h"

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <unordered_map>

#include "core/parallel/parallel_for.h"

namespace sdf {
namespace {

struct PositionKey {
    double x, y, z;
    bool operator==(const PositionKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PositionHash {
    size_t operator()(const PositionKey& k) const {
        std::hash<double> h;
        return h(k.x) ^ (h(k.y) * 0x9e3779b97f4a7c15ull) ^ (h(k.z) * 0xc2b2ae3d27d4eb4full);
    }
};

/// A hash of a position that positions comparing equal share (0.0 and -0.0 included).
uint64_t position_hash(const Vec3d& p) {
    const auto mix = [](uint64_t h) {  // MurmurHash3's finaliser
        h ^= h >> 33;
        h *= 0xff51afd7ed558ccdull;
        h ^= h >> 33;
        h *= 0xc4ceb9fe1a85ec53ull;
        return h ^ (h >> 33);
    };
    const auto bits = [](double d) {
        d = d == 0.0 ? 0.0 : d;
        uint64_t b;
        std::memcpy(&b, &d, sizeof b);
        return b;
    };
    return mix(bits(p.x) ^ mix(bits(p.y) ^ mix(bits(p.z))));
}

}  // namespace

std::vector<int> weld_vertices(const std::vector<Vec3d>& in, double tolerance, std::vector<Vec3d>& out) {
    std::vector<int> remap(in.size());
    std::unordered_map<PositionKey, std::vector<int>, PositionHash> cells;
    auto cell_of = [&](const Vec3d& p) {
        return tolerance > 0 ? PositionKey{std::floor(p.x / tolerance), std::floor(p.y / tolerance), std::floor(p.z / tolerance)}
                             : PositionKey{p.x, p.y, p.z};
    };
    for (size_t i = 0; i < in.size(); ++i) {
        const PositionKey c = cell_of(in[i]);
        int found = -1;
        const int reach = tolerance > 0 ? 1 : 0;
        for (int dz = -reach; dz <= reach && found < 0; ++dz)
            for (int dy = -reach; dy <= reach && found < 0; ++dy)
                for (int dx = -reach; dx <= reach && found < 0; ++dx) {
                    auto it = cells.find({c.x + dx, c.y + dy, c.z + dz});
                    if (it == cells.end()) continue;
                    for (int id : it->second)
                        if (tolerance > 0 ? length(out[size_t(id)] - in[i]) <= tolerance : true) { found = id; break; }
                }
        if (found < 0) {
            found = int(out.size());
            out.push_back(in[i]);
            cells[c].push_back(found);
        }
        remap[i] = found;
    }
    return remap;
}

bool welds_like(const std::vector<Vec3d>& in, const std::vector<int>& weld, std::vector<Vec3d>& welded, int threads) {
    if (weld.size() != in.size()) return false;
    std::vector<size_t> first;  // each group's first vertex: ids are numbered in order of first appearance
    for (size_t i = 0; i < in.size(); ++i) {
        if (size_t(weld[i]) == first.size()) first.push_back(i);
        else if (size_t(weld[i]) > first.size() || weld[i] < 0) return false;
    }
    std::atomic<bool> same{true};
    parallel_for(int64_t(in.size()), 16384, threads, [&](int64_t i0, int64_t i1) {
        for (int64_t i = i0; i < i1 && same.load(std::memory_order_relaxed); ++i) {
            const Vec3d& p = in[size_t(i)];
            if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) || !(p == in[first[size_t(weld[size_t(i)])]]))
                same = false;
        }
    });
    if (!same) return false;
    welded.resize(first.size());
    for (size_t g = 0; g < first.size(); ++g) welded[g] = in[first[g]];
    size_t capacity = 1;
    while (capacity < 2 * welded.size()) capacity <<= 1;
    std::vector<int> table(capacity, -1);
    for (size_t g = 0; g < welded.size(); ++g) {
        size_t slot = size_t(position_hash(welded[g])) & (capacity - 1);
        for (; table[slot] >= 0; slot = (slot + 1) & (capacity - 1))
            if (welded[size_t(table[slot])] == welded[g]) return false;  // two groups at one position: they weld now
        table[slot] = int(g);
    }
    return true;
}

}  // namespace sdf
