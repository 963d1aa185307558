#include "core/lattice/lattice_fitting.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "core/checked_math.h"

namespace sdf {

Lattice fit_lattice(LatticeType type, Int3 resolution, const Bounds3& bounds, double margin, LatticeStorage storage) {
    for (int a = 0; a < 3; ++a)
        if (resolution[a] < 2)
            throw std::invalid_argument("lattice resolution must be at least 2 along every axis, got " +
                                        std::to_string(resolution[a]));
    checked_lattice_points(type, resolution, storage);
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

int64_t checked_lattice_points(LatticeType type, Int3 r, LatticeStorage storage) {
    const bool bcc = type == LatticeType::BCC;
    const std::string notation = std::to_string(r.x) + "x" + std::to_string(r.y) + "x" +
                                 std::to_string(bcc ? 2 * int64_t(r.z) : int64_t(r.z));
    if (r.x < 1 || r.y < 1 || r.z < 1)
        throw std::invalid_argument("lattice resolution " + notation + ": every entry must be positive");
    // BCC: the primary grid plus the secondary grid (one fewer point per axis).
    const std::optional<int64_t> primary = checked_mul(r.x, r.y, r.z);
    const std::optional<int64_t> secondary = bcc ? checked_mul(r.x - 1, r.y - 1, r.z - 1) : int64_t(0);
    const std::optional<int64_t> total = primary && secondary ? checked_add(*primary, *secondary) : std::nullopt;
    const int64_t most = max_lattice_points(storage);
    if (!total || *total > most) {
        const bool dense = storage == LatticeStorage::Dense;
        throw std::invalid_argument("lattice resolution " + notation + " has " +
                                    (total ? std::to_string(*total) : std::string("more than 2^63")) +
                                    " points, more than the largest lattice sampled " +
                                    (dense ? "densely (2^36 = " : "as a sparse band (2^42 = ") + std::to_string(most) +
                                    (dense ? "; a sparse narrow band may have up to 2^42)" : ")"));
    }
    return *total;
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
    for (int r = 2; r <= 16384; ++r) {  // 16384^3: the largest sparse band's lattice
        if (std::llabs(cubic_lattice_points(type, r) - samples) < std::llabs(cubic_lattice_points(type, best) - samples))
            best = r;
        if (cubic_lattice_points(type, r) > samples) break;
    }
    return best;
}

}  // namespace sdf
