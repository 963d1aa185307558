#include "core/sampling/sparse_band_cells.h"

#include <algorithm>
#include <cmath>

namespace sdf {

bool in_band_cells(const SparseBandField& band, const Vec3d& p) {
    const BandLayout& layout = band.layout();
    const double h = band.lattice.spacing;
    for (int c = 0; c < layout.cosets(); ++c) {
        const BandCoset& s = layout.coset(c);
        const Vec3d origin = band.lattice.origin + Vec3d(double(s.first.x), double(s.first.y), double(s.first.z)) * (0.5 * h);
        const Vec3d u = (p - origin) / h;
        const double q[3] = {u.x, u.y, u.z};
        const int n[3] = {s.points.x, s.points.y, s.points.z};
        int cell[3];
        for (int a = 0; a < 3; ++a) {
            if (!(q[a] >= 0) || !(q[a] <= double(n[a] - 1)) || n[a] < 2) return false;  // NaN too
            cell[a] = std::min(int(std::floor(q[a])), n[a] - 2);  // the last plane belongs to the last cell
        }
        for (int corner = 0; corner < 8; ++corner) {
            const Int3 point{cell[0] + (corner & 1), cell[1] + (corner >> 1 & 1), cell[2] + (corner >> 2 & 1)};
            const Int3 block{point.x / kBandBlockDim, point.y / kBandBlockDim, point.z / kBandBlockDim};
            const int local = point.x % kBandBlockDim + kBandBlockDim * (point.y % kBandBlockDim + kBandBlockDim * (point.z % kBandBlockDim));
            const int64_t a = band.find_active(layout.block_id(c, block));
            if (a < 0 || !band.in_band(size_t(a), local)) return false;
        }
    }
    return true;
}

}  // namespace sdf
