/// @file stitch_rings.h
/// @brief Joins two rings of vertex ids (around an axis, or around a panel) with a strip of
/// triangles; used by the pawn (surface of revolution) and the soccer ball (panel rings).
#pragma once

#include <vector>

#include "kernels/core/vec3.h"

namespace sdf {

/// Walks both rings in the same direction, always advancing the ring whose next vertex comes
/// first (compared exactly, in integers). A one-vertex ring (a pole, a panel centre) never
/// advances, so the strip becomes a fan. Rings of m and n > 1 vertices give m + n triangles.
inline void stitch_rings(const std::vector<int>& lo, const std::vector<int>& hi, std::vector<Int3>& triangles) {
    const int m = int(lo.size()), n = int(hi.size());
    const int lo_steps = m > 1 ? m : 0, hi_steps = n > 1 ? n : 0;
    for (int i = 0, j = 0; i < lo_steps || j < hi_steps;) {
        const bool advance_lo = j == hi_steps || (i < lo_steps && (i + 1) * n <= (j + 1) * m);
        const int a = lo[size_t(i % m)], b = hi[size_t(j % n)];
        if (advance_lo) {
            ++i;
            triangles.push_back({a, b, lo[size_t(i % m)]});
        } else {
            ++j;
            triangles.push_back({a, b, hi[size_t(j % n)]});
        }
    }
}

}  // namespace sdf
