#include "core/sampling/certified_search.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/parallel/parallel_for.h"

namespace sdf {
FloatSearchBound float_search_bound(const PreparedMesh& mesh) { return mesh.search_bound(); }

namespace {

template <typename Points>
double largest_of(const Points& points, int threads) {
    constexpr int64_t kChunk = 1 << 16;
    const int64_t n = point_count(points), chunks = (n + kChunk - 1) / kChunk;
    std::vector<double> largest(size_t(std::max<int64_t>(chunks, 1)), 0.0);
    parallel_for(chunks, 1, chunks > 1 ? threads : 1, [&](int64_t c0, int64_t c1) {
        for (int64_t c = c0; c < c1; ++c) {
            double m = 0;
            for (int64_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) m = std::max(m, largest_coordinate(point_at(points, i)));
            largest[size_t(c)] = m;
        }
    });
    return *std::max_element(largest.begin(), largest.end());
}

}  // namespace

double largest_coordinate(const std::vector<Vec3d>& points, int threads) { return largest_of(points, threads); }
double largest_coordinate(const HostPoints& points, int threads) { return largest_of(points, threads); }

CertificateReport certificate_provenance(bool float_search, bool certified, const CertificateCounters& counters) {
    CertificateReport c;
    if (!float_search) {
        c.note = "double search: the reference";
        return c;
    }
    c.certified = certified;
    if (!certified) {
        c.note = "uncertified: the float search's own winner (near-ties may differ from the double search)";
        return c;
    }
    c.counted = true;
    c.points = counters.points.load();
    c.reranked_in_double = counters.reranked.load();
    c.full_double_search = counters.full_double.load();
    return c;
}

}  // namespace sdf
