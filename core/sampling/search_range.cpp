#include "core/sampling/search_range.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

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

void require_search_range(const PreparedMesh& mesh, const std::vector<Vec3d>& points, Precision precision) {
    require_mesh_in_range(mesh, precision);
    for (size_t i = 0; i < points.size(); ++i)
        if (!std::isfinite(points[i].x + points[i].y + points[i].z) ||
            largest_magnitude(points[i]) > largest_search_coordinate(precision))
            require_point_in_range(points[i], precision, "query points: row " + std::to_string(i));
}

void require_search_range(const PreparedMesh& mesh, Precision precision) { require_mesh_in_range(mesh, precision); }

void require_query_point_in_range(const Vec3d& p, int64_t index, Precision precision) {
    require_point_in_range(p, precision, "query points: row " + std::to_string(index));
}

}  // namespace sdf
