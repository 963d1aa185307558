#include "core/sampling/search_range.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "core/parallel/parallel_for.h"

namespace sdf {
namespace {

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", v);
    return text;
}

const char* precision_word(Precision p) { return p == Precision::Float ? "float" : "double"; }

double largest_magnitude(const Vec3d& p) { return std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}); }

void require_mesh_in_range(const PreparedMesh& mesh, Precision precision) {
    const Bounds3& b = mesh.bounds();
    const std::string who = "mesh '" + mesh.name() + "' (" + mesh.source() + ")";
    const double reach = std::max(largest_magnitude(b.min), largest_magnitude(b.max));
    const Vec3d e = b.extent();
    const double extent = std::max({e.x, e.y, e.z});
    const double largest = largest_search_coordinate(precision), smallest = smallest_search_extent(precision);
    const std::string hint = precision == Precision::Float ? "; use precision double (--precision double, "
                                                             "\"precision\": \"double\")"
                                                           : "; scale the mesh";
    if (reach > largest)
        throw std::invalid_argument(who + " has coordinates of magnitude " + number(reach) + ", beyond the " +
                                    precision_word(precision) + " search's range of " + number(largest) +
                                    " (squared distances would overflow)" + hint);
    if (extent < smallest)
        throw std::invalid_argument(who + " is only " + number(extent) + " across, below the " +
                                    precision_word(precision) + " search's smallest extent of " + number(smallest) +
                                    " (squared distances would underflow and lose the nearest triangle)" + hint);
}

void require_point_in_range(const Vec3d& p, Precision precision, const std::string& which) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw std::invalid_argument(which + " is not finite (" + number(p.x) + ", " + number(p.y) + ", " + number(p.z) + ")");
    const double m = largest_magnitude(p);
    if (m > largest_search_coordinate(precision))
        throw std::invalid_argument(which + " has a coordinate of magnitude " + number(m) + ", beyond the " +
                                    precision_word(precision) + " search's range of " +
                                    number(largest_search_coordinate(precision)) +
                                    " (squared distances would overflow)" +
                                    (precision == Precision::Float ? "; use precision double" : ""));
}

}  // namespace

double largest_search_coordinate(Precision precision) {
    return precision == Precision::Float ? std::ldexp(1.0, 60) : std::ldexp(1.0, 500);
}

double smallest_search_extent(Precision precision) {
    return precision == Precision::Float ? std::ldexp(1.0, -40) : std::ldexp(1.0, -450);
}

void require_search_range(const PreparedMesh& mesh, const Lattice& lattice, Precision precision) {
    require_mesh_in_range(mesh, precision);
    // The primary grid's box, widened by a spacing: it holds every point of either lattice.
    const Vec3d h{lattice.spacing, lattice.spacing, lattice.spacing};
    const std::string which = "the lattice " + std::string(lattice_type_name(lattice.type)) +
                              " of spacing " + number(lattice.spacing);
    require_point_in_range(lattice.domain_min() - h, precision, which);
    require_point_in_range(lattice.domain_max() + h, precision, which);
}

namespace {

template <typename Points>
void require_points_in_range(const PreparedMesh& mesh, const Points& points, Precision precision, int threads) {
    require_mesh_in_range(mesh, precision);
    // The first bad row of each chunk, then the first of those: the same row on any thread count.
    constexpr int64_t kChunk = 1 << 16;
    const int64_t n = point_count(points), chunks = (n + kChunk - 1) / kChunk;
    const double limit = largest_search_coordinate(precision);
    std::vector<int64_t> first_bad(size_t(chunks), n);
    parallel_for(chunks, 1, threads, [&](int64_t c0, int64_t c1) {
        for (int64_t c = c0; c < c1; ++c)
            for (int64_t i = c * kChunk; i < std::min(n, (c + 1) * kChunk); ++i) {
                const Vec3d p = point_at(points, i);
                if (!std::isfinite(p.x + p.y + p.z) || largest_magnitude(p) > limit) {
                    first_bad[size_t(c)] = i;
                    break;
                }
            }
    });
    for (const int64_t i : first_bad)
        if (i < n) require_point_in_range(point_at(points, i), precision, "query points: row " + std::to_string(i));
}

}  // namespace

void require_search_range(const PreparedMesh& mesh, const std::vector<Vec3d>& points, Precision precision, int threads) {
    require_points_in_range(mesh, points, precision, threads);
}

void require_search_range(const PreparedMesh& mesh, const HostPoints& points, Precision precision, int threads) {
    require_points_in_range(mesh, points, precision, threads);
}

void require_search_range(const PreparedMesh& mesh, Precision precision) { require_mesh_in_range(mesh, precision); }

void require_query_point_in_range(const Vec3d& p, int64_t index, Precision precision) {
    require_point_in_range(p, precision, "query points: row " + std::to_string(index));
}

}  // namespace sdf
