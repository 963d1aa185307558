#include "core/sampling/sparse_band_window.h"

#include <stdexcept>
#include <string>

#include "core/lattice/lattice_fitting.h"

namespace sdf {

Lattice LatticeWindow::lattice_in(const Lattice& parent) const {
    Lattice l = parent;
    l.resolution = resolution;
    l.origin = parent.position_of_coords({2 * first.x, 2 * first.y, 2 * first.z});
    return l;
}

bool LatticeWindow::fits(const Lattice& parent) const {
    for (int a = 0; a < 3; ++a)
        if (first[a] < 0 || resolution[a] < 1 || int64_t(first[a]) + resolution[a] > parent.resolution[a]) return false;
    return true;
}

SampledField densify_window(const SparseBandField& band, const LatticeWindow& window, bool gradient) {
    if (!window.fits(band.lattice))
        throw std::invalid_argument("densify_window: primary points [" + std::to_string(window.first.x) + ", " +
                                    std::to_string(window.first.y) + ", " + std::to_string(window.first.z) + "] + [" +
                                    std::to_string(window.resolution.x) + ", " + std::to_string(window.resolution.y) + ", " +
                                    std::to_string(window.resolution.z) + "] are not a window of " + lattice_notation(band.lattice));
    const BandLayout& layout = band.layout();
    SampledField field;
    field.lattice = window.lattice_in(band.lattice);
    field.precision = band.precision;
    field.resize(field.lattice.num_points());
    const bool band_gradient = !band.gradient.empty(), band_triangle = band.channels.closest_triangle;
    // Points are visited x fastest, so consecutive ones mostly share a block: its kind is
    // looked up (a binary search of the active and the mixed ids) once per change of block.
    int64_t block = -1, active = -1, mixed = -1;
    int64_t out = 0;  // the window's storage order: coset by coset, x fastest (kernels/lattice/lattice.h)
    for (int c = 0; c < layout.cosets(); ++c) {
        const Int3 n = c == 0 ? window.resolution : Int3{window.resolution.x - 1, window.resolution.y - 1, window.resolution.z - 1};
        for (int z = 0; z < n.z; ++z)
            for (int y = 0; y < n.y; ++y)
                for (int x = 0; x < n.x; ++x, ++out) {
                    // Coset point (i, j, k) of the window is the parent's (first + (i, j, k)), on
                    // either coset (a secondary point lies between the primary ones it follows).
                    const Int3 p{window.first.x + x, window.first.y + y, window.first.z + z};
                    const Int3 b{p.x / kBandBlockDim, p.y / kBandBlockDim, p.z / kBandBlockDim};
                    const int local = p.x % kBandBlockDim + kBandBlockDim * (p.y % kBandBlockDim + kBandBlockDim * (p.z % kBandBlockDim));
                    const int64_t id = layout.block_id(c, b);
                    if (id != block) {
                        block = id;
                        active = band.find_active(id);
                        mixed = active < 0 ? band.find_mixed(id) : -1;
                    }
                    if (active >= 0) {
                        const size_t v = size_t(active) * kBandBlockPoints + size_t(local);
                        field.distance[size_t(out)] = band.distance[v];
                        if (band_gradient) field.gradient[size_t(out)] = band.gradient[v];
                        if (band_triangle) field.closest_triangle[size_t(out)] = band.closest_triangle[v];
                    } else {
                        const bool inside = mixed >= 0 ? (band.mixed_inside[size_t(mixed)][size_t(local >> 6)] >> (local & 63)) & 1
                                                       : band.tile_inside(id);
                        store_outside_band(field, out, inside, band.distance.rounded(band.width));  // the triangle channel cleared below if not held
                    }
                }
    }
    if (!gradient) field.gradient.clear();
    if (!band_triangle) field.closest_triangle.clear();  // a band without triangles: none (nor -1s) in its windows
    return field;
}

}  // namespace sdf
