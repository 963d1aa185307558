#include "experiments/common/lattice_points.h"

#include <algorithm>

namespace sdf {

std::vector<Vec3d> lattice_points(const Lattice& lattice) {
    std::vector<Vec3d> points(size_t(lattice.num_points()));
    for (int64_t i = 0; i < lattice.num_points(); ++i) points[size_t(i)] = lattice.position(i);
    return points;
}

LatticeSubset strided_lattice_subset(const Lattice& lattice, int64_t count) {
    const int64_t n = lattice.num_points();
    const int64_t m = count > 0 ? std::min(count, n) : n;
    const int64_t stride = std::max<int64_t>(1, n / m);
    LatticeSubset s;
    for (int64_t i = 0; i < n && int64_t(s.points.size()) < m; i += stride) {
        s.index.push_back(i);
        s.points.push_back(lattice.position(i));
    }
    return s;
}

}  // namespace sdf
