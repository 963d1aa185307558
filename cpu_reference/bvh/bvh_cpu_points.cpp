#include "cpu_reference/bvh/bvh_cpu_points.h"

#include <algorithm>
#include <array>
#include <memory>

#include "core/parallel/parallel_for.h"
#include "kernels/core/morton.h"

namespace sdf::cpu_bvh {

namespace {

/// The points' order by Morton key (ties by index): a least-significant-digit radix sort of
/// (key << 32 | index), 4 passes of 8 bits, every step on `threads` threads. Each pass counts
/// the digits of fixed chunks of the items, and each chunk scatters its items to the offsets
/// that the counts give it in order: a stable pass, so the order does not depend on the
/// threads (the words are distinct, so there is one sorted order).
template <typename Points>
std::vector<uint32_t> morton_order_of(const Points& points, int threads) {
    const int64_t n = point_count(points);
    if (n == 0) return {};
    constexpr int64_t kChunk = 1 << 16;
    const int64_t chunks = (n + kChunk - 1) / kChunk;
    auto chunk_end = [&](int64_t c) { return std::min(n, (c + 1) * kChunk); };
    std::vector<Vec3d> chunk_lo(static_cast<size_t>(chunks)), chunk_hi(static_cast<size_t>(chunks));
    parallel_for(chunks, 1, threads, [&](int64_t c0, int64_t c1) {
        for (int64_t c = c0; c < c1; ++c) {
            Vec3d lo = point_at(points, c * kChunk), hi = lo;
            for (int64_t i = c * kChunk; i < chunk_end(c); ++i) {
                const Vec3d p = point_at(points, i);
                lo = component_min(lo, p);
                hi = component_max(hi, p);
            }
            chunk_lo[size_t(c)] = lo;
            chunk_hi[size_t(c)] = hi;
        }
    });
    Vec3d lo = chunk_lo[0], hi = chunk_hi[0];
    for (int64_t c = 0; c < chunks; ++c) {
        lo = component_min(lo, chunk_lo[size_t(c)]);
        hi = component_max(hi, chunk_hi[size_t(c)]);
    }
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const double inv_extent = extent > 0 ? 1.0 / extent : 0.0;
    // key (top 30 of 63 bits) << 32 | index: sorting the word sorts by key, then by index.
    // Uninitialised storage: every word is written by the chunk that owns it.
    std::unique_ptr<uint64_t[]> items(new uint64_t[size_t(n)]), scratch(new uint64_t[size_t(n)]);
    parallel_for(chunks, 1, threads, [&](int64_t c0, int64_t c1) {
        for (int64_t i = c0 * kChunk; i < chunk_end(c1 - 1); ++i) {
            const Vec3d p = point_at(points, i);
            const uint64_t key = morton_key_of_point(p.x, p.y, p.z, lo.x, lo.y, lo.z, inv_extent) >> 33;
            items[size_t(i)] = key << 32 | uint64_t(i);
        }
    });
    std::vector<std::array<int64_t, 256>> offset(static_cast<size_t>(chunks));
    for (int pass = 0; pass < 4; ++pass) {
        const int shift = 32 + 8 * pass;
        parallel_for(chunks, 1, threads, [&](int64_t c0, int64_t c1) {
            for (int64_t c = c0; c < c1; ++c) {
                std::array<int64_t, 256>& count = offset[size_t(c)];
                count.fill(0);
                for (int64_t i = c * kChunk; i < chunk_end(c); ++i) ++count[(items[size_t(i)] >> shift) & 0xff];
            }
        });
        int64_t at = 0;  // digit-major, chunk-minor: each chunk's first slot for each digit
        for (int d = 0; d < 256; ++d)
            for (int64_t c = 0; c < chunks; ++c) {
                const int64_t count = offset[size_t(c)][size_t(d)];
                offset[size_t(c)][size_t(d)] = at;
                at += count;
            }
        parallel_for(chunks, 1, threads, [&](int64_t c0, int64_t c1) {
            for (int64_t c = c0; c < c1; ++c) {
                std::array<int64_t, 256>& next = offset[size_t(c)];
                for (int64_t i = c * kChunk; i < chunk_end(c); ++i) {
                    const uint64_t v = items[size_t(i)];
                    scratch[size_t(next[(v >> shift) & 0xff]++)] = v;
                }
            }
        });
        items.swap(scratch);
    }
    std::vector<uint32_t> order(static_cast<size_t>(n));
    parallel_for(n, 1 << 16, threads, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) order[size_t(i)] = uint32_t(items[size_t(i)]);
    });
    return order;
}

}  // namespace

std::vector<uint32_t> morton_order(const std::vector<Vec3d>& points, int threads) { return morton_order_of(points, threads); }
std::vector<uint32_t> morton_order(const HostPoints& points, int threads) { return morton_order_of(points, threads); }

}  // namespace sdf::cpu_bvh
