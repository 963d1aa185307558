#include "core/sampling/host_query.h"

#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/parallel/parallel_for.h"
#include "core/sampling/sampler.h"

namespace sdf {

namespace {
constexpr int64_t kRowsPerTask = 1 << 16;
}

void require_finite_points(const HostPoints& points, const std::string& argument, int threads) {
    // The smallest bad row, whichever thread finds it first: the message is the same every run.
    std::atomic<int64_t> first_bad{std::numeric_limits<int64_t>::max()};
    parallel_for(points.count, kRowsPerTask, threads, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e && i < first_bad.load(std::memory_order_relaxed); ++i) {
            const Vec3d p = points[i];
            if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) continue;
            int64_t seen = first_bad.load();
            while (i < seen && !first_bad.compare_exchange_weak(seen, i)) {}
            return;
        }
    });
    if (first_bad.load() != std::numeric_limits<int64_t>::max())
        throw std::invalid_argument(argument + ": row " + std::to_string(first_bad.load()) + " is not three finite numbers");
}

std::vector<Vec3d> gather_points(const HostPoints& points, const std::string& argument, int threads) {
    require_finite_points(points, argument, threads);
    std::vector<Vec3d> out(size_t(points.count));
    parallel_for(points.count, kRowsPerTask, threads, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) out[size_t(i)] = points[i];
    });
    return out;
}

void store_result(const HostQueryResults& r, int64_t i, const PointSample& s) {
    if (r.distance) r.distance[i] = s.distance;
    if (r.gradient) {
        r.gradient[3 * i] = s.gradient.x;
        r.gradient[3 * i + 1] = s.gradient.y;
        r.gradient[3 * i + 2] = s.gradient.z;
    }
    if (r.triangle) r.triangle[i] = s.triangle;
}

void scatter_samples(const std::vector<PointSample>& samples, const HostQueryResults& r, int threads) {
    parallel_for(int64_t(samples.size()), kRowsPerTask, threads, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) store_result(r, i, samples[size_t(i)]);
    });
}

}  // namespace sdf
