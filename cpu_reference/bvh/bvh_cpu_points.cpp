#include "cpu_reference/bvh/bvh_cpu_points.h"

#include <algorithm>

#include "kernels/core/morton.h"

namespace sdf::cpu_bvh {

std::vector<uint32_t> morton_order(const std::vector<Vec3d>& points, int threads) {
    const size_t n = points.size();
    Vec3d lo = points[0], hi = points[0];
    for (const Vec3d& p : points) {
        lo = component_min(lo, p);
        hi = component_max(hi, p);
    }
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const double inv_extent = extent > 0 ? 1.0 / extent : 0.0;
    // key (top 30 of 63 bits) << 32 | index: sorting the word sorts by key, then by index.
    std::vector<uint64_t> items(n), scratch(n);
    parallel_for(int64_t(n), 1 << 14, threads, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
            const Vec3d& p = points[size_t(i)];
            const uint64_t key = morton_key_of_point(p.x, p.y, p.z, lo.x, lo.y, lo.z, inv_extent) >> 33;
            items[size_t(i)] = key << 32 | uint64_t(i);
        }
    });
    for (int pass = 0; pass < 4; ++pass) {
        const int shift = 32 + 8 * pass;
        size_t count[257] = {};
        for (uint64_t v : items) ++count[((v >> shift) & 0xff) + 1];
        for (int d = 0; d < 256; ++d) count[d + 1] += count[d];
        for (uint64_t v : items) scratch[count[(v >> shift) & 0xff]++] = v;
        items.swap(scratch);
    }
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = uint32_t(items[i]);
    return order;
}

}  // namespace sdf::cpu_bvh
