/// @file lattice_field_view.h
/// @brief The POD that every interpolator reads: lattice geometry, the sampled values and the
/// per-point derivative arrays ("Hermite data") that the chosen derivative source produced.
///
/// The view owns nothing; the host (core/reconstruction/hermite_data.h) or a CUDA
/// uploader fills the arrays and points the view at them. All derivatives are stored per
/// *lattice unit* u, where world = origin + unit * u: unit = h on CC (a cell is [0,1]^3) and
/// unit = h/2 on BCC (integer coordinates of lattice.h, neighbours at (+-1,+-1,+-1) and
/// (+-2,0,0) as in thesis Figure 4-2). So a stored first derivative is h * df/dx (CC) or
/// (h/2) * df/dx (BCC), and a k-th derivative carries unit^k.
#pragma once

#include <cstdint>

#include "kernels/lattice/lattice.h"

namespace sdf {

/// Slots of LatticeFieldView::higher for the CC tricubic (Lekien-Marsden) data.
enum CcHigherSlot : int { kCcDxy = 0, kCcDxz = 1, kCcDyz = 2, kCcDxyz = 3, kCcHigherStride = 4 };

/// Slots of LatticeFieldView::higher for BCC data: the mixed second derivatives the thesis's
/// objective (eq. 4-3) uses, then the pure ones (read only by bcc_cubic_c0).
enum BccHigherSlot : int { kBccDxy = 0, kBccDxz = 1, kBccDyz = 2, kBccDxx = 3, kBccDyy = 4, kBccDzz = 5,
                           kBccMixedStride = 3, kBccFullStride = 6 };

/// Per-vertex data of a BCC cubic in the reference tetrahedron's frame (bcc_tetrahedron.h):
/// f, fx, fy, fz, fxy, fxz, fyz, fxx, fyy, fzz.
enum BccDatum : int { kDf = 0, kDx = 1, kDy = 2, kDz = 3, kDxy = 4, kDxz = 5, kDyz = 6,
                      kDxx = 7, kDyy = 8, kDzz = 9, kBccData = 10 };

/// Weights that give the 4 face-centre Bernstein-Bezier coefficients of the BCC cubic on the
/// reference tetrahedron as linear combinations of its vertex data:
///   c_face[l] = sum_v sum_k w[v][k][l] * data[v][k]   (face l is opposite vertex l).
/// Filled on the host (bcc_cubic_tables.h): thesis eq. 4-9 for bcc_cubic, a face-local
/// least-squares fit for bcc_cubic_c0. POD, passed by value (1.3 KB in double). The face
/// index runs fastest so the 4 sums advance together (one SIMD lane each).
template <typename T>
struct BccFaceTable {
    T w[4][kBccData][4];  ///< [vertex][datum][face]
};

template <typename T>
struct LatticeFieldView {
    Lattice lattice{};          ///< geometry and storage order (kernels/lattice/lattice.h)
    Vec3<T> origin{};           ///< lattice.origin in T
    T unit{1};                  ///< world length of one lattice unit: h (CC) or h/2 (BCC)
    T inv_unit{1};
    const T* values = nullptr;      ///< f at every point, storage order
    const Vec3<T>* first = nullptr; ///< df/du at every point (true or estimated), or null
    const T* higher = nullptr;      ///< higher derivatives, `higher_stride` per point, or null;
                                    ///< for the prefiltered splines their coefficients (stride 1)
    int higher_stride = 0;          ///< 0, 1, kCcHigherStride, kBccMixedStride or kBccFullStride
    BccFaceTable<T> bcc_faces{};    ///< for bcc_cubic / bcc_cubic_c0

    /// Lattice coordinates of a world point.
    SDF_CPU_GPU Vec3<T> to_lattice(const Vec3<T>& p) const { return (p - origin) * inv_unit; }
    SDF_CPU_GPU Vec3<T> to_world(const Vec3<T>& u) const { return origin + u * unit; }
};

/// Storage index of CC grid point (i, j, k); no bounds check outside debug builds.
SDF_CPU_GPU inline int64_t cc_index(const Lattice& l, int i, int j, int k) {
    SDF_DCHECK(i >= 0 && j >= 0 && k >= 0 && i < l.resolution.x && j < l.resolution.y && k < l.resolution.z);
    return i + int64_t(l.resolution.x) * (j + int64_t(l.resolution.y) * k);
}

/// Storage index of the BCC point with integer coordinates c (units of h/2, all even or all
/// odd, inside the lattice); the fast path of Lattice::index_of_coords.
SDF_CPU_GPU inline int64_t bcc_index(const Lattice& l, const Int3& c) {
    SDF_DCHECK(l.index_of_coords(c) >= 0);
    const int odd = c.x & 1;
    const int rx = l.resolution.x - odd, ry = l.resolution.y - odd;
    const int64_t local = (c.x >> 1) + int64_t(rx) * ((c.y >> 1) + int64_t(ry) * (c.z >> 1));
    return odd ? l.primary_count() + local : local;
}

}  // namespace sdf
