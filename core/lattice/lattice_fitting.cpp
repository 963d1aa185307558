#include "core/lattice/lattice_fitting.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace sdf {

Lattice fit_lattice(LatticeType type, Int3 resolution, const Bounds3& bounds, double margin) {
    for (int a = 0; a < 3; ++a)
        if (resolution[a] < 2)
            throw std::invalid_argument("lattice resolution must be at least 2 along every axis, got " +
                                        std::to_string(resolution[a]));
    if (bounds.empty()) throw std::invalid_argument("cannot fit a lattice to an empty mesh");
    const Vec3d extent = bounds.extent();
    const double largest = std::max({extent.x, extent.y, extent.z});
    const double pad = margin * largest;
    double spacing = 0;
    for (int a = 0; a < 3; ++a) spacing = std::max(spacing, (extent[a] + 2 * pad) / (resolution[a] - 1));
    if (!(spacing > 0)) spacing = 1.0;  // a single point: any spacing
    Lattice lattice;
    lattice.type = type;
    lattice.spacing = spacing;
    lattice.resolution = resolution;
    const Vec3d center = bounds.center();
    for (int a = 0; a < 3; ++a) lattice.origin[a] = center[a] - 0.5 * spacing * (resolution[a] - 1);
    return lattice;
}

std::string lattice_notation(const Lattice& l) {
    const int z = l.type == LatticeType::BCC ? 2 * l.resolution.z : l.resolution.z;
    return std::to_string(l.resolution.x) + "x" + std::to_string(l.resolution.y) + "x" + std::to_string(z);
}

Int3 bcc_primary_from_notation(Int3 n) {
    if (n.z % 2 != 0)
        throw std::invalid_argument("BCC resolution is written Rx x Ry x 2Rz, so its third entry must be even; got " +
                                    std::to_string(n.z));
    return {n.x, n.y, n.z / 2};
}

int64_t cubic_lattice_points(LatticeType type, int r) {
    const int64_t a = int64_t(r) * r * r;
    const int64_t b = int64_t(r - 1) * (r - 1) * (r - 1);
    return type == LatticeType::CC ? a : a + b;
}

int cubic_resolution_for_samples(LatticeType type, int64_t samples) {
    int best = 2;
    for (int r = 2; r < 4096; ++r) {
        if (std::llabs(cubic_lattice_points(type, r) - samples) < std::llabs(cubic_lattice_points(type, best) - samples))
            best = r;
        if (cubic_lattice_points(type, r) > samples) break;
    }
    return best;
}

}  // namespace sdf
