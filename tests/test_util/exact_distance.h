/// @file exact_distance.h
/// @brief Exact point-triangle squared distances (CGAL, rational arithmetic) for tests: the
/// independent truth the searches' slivers are checked against. Tests only: slow.
#pragma once

#include <CGAL/Exact_rational.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/squared_distance_3.h>

#include <vector>

#include "core/mesh/triangle_mesh.h"

namespace sdf::test {

using ExactKernel = CGAL::Simple_cartesian<CGAL::Exact_rational>;

inline ExactKernel::Point_3 exact_point(const Vec3d& p) { return {p.x, p.y, p.z}; }

/// The exact squared distance from p to triangle (a, b, c), as an exact number.
inline ExactKernel::FT exact_squared_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const ExactKernel::Point_3 pa = exact_point(a), pb = exact_point(b), pc = exact_point(c);
    if (CGAL::collinear(pa, pb, pc)) {  // CGAL's triangle needs an area: the nearest of its edges
        ExactKernel::FT best = CGAL::squared_distance(exact_point(p), ExactKernel::Segment_3(pa, pb));
        for (const auto& s : {ExactKernel::Segment_3(pb, pc), ExactKernel::Segment_3(pc, pa)}) {
            const ExactKernel::FT d = CGAL::squared_distance(exact_point(p), s);
            if (d < best) best = d;
        }
        return best;
    }
    return CGAL::squared_distance(exact_point(p), ExactKernel::Triangle_3(pa, pb, pc));
}

/// Exact squared distances from p to every triangle of `mesh` (rounded to double).
inline std::vector<double> exact_squared_distances(const TriangleMesh& mesh, const Vec3d& p) {
    std::vector<double> q;
    q.reserve(mesh.triangles.size());
    for (const Int3& t : mesh.triangles)
        q.push_back(CGAL::to_double(exact_squared_distance(p, mesh.vertices[size_t(t.x)], mesh.vertices[size_t(t.y)],
                                                           mesh.vertices[size_t(t.z)])));
    return q;
}

}  // namespace sdf::test
