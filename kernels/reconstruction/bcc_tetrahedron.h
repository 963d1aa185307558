/// @file bcc_tetrahedron.h
/// @brief Point location in the Delaunay tetrahedralisation of the BCC lattice, without
/// search, and the symmetry that maps every tetrahedron onto one reference tetrahedron.
///
/// The Delaunay tetrahedralisation of BCC is unique and its tetrahedra are congruent (thesis
/// section 1.2, Figure 1-1 B). In integer coordinates (units of h/2, lattice.h): the two
/// secondary points at the centres of two primary cubes that share a face, (1,1,1) and
/// (1,1,-1), and the four primary corners of that face form an octahedron; its unique
/// Delaunay split is along the short secondary edge, into 4 tetrahedra, each made of that
/// secondary edge and one edge of the square face. So every tetrahedron has 2 secondary and
/// 2 primary vertices; edges: 2 axis edges of length 2 (opposite, perpendicular) and 4
/// body-diagonal edges of length sqrt(3).
///
/// Location: the primary cube holding u is found by flooring; its centre S0 is the apex of 6
/// square pyramids, one per face; the pyramid holding u is given by the axis a of the
/// largest |u - S0| component and its sign; the pyramid splits into 4 pieces by its
/// diagonal planes, chosen by the larger of the two other components (axis b, the smaller
/// one is axis c). The tetrahedron is (S0, S0 + 2 s_a e_a) with the face edge
/// S0 + s_a e_a + s_b e_b -+ e_c.
///
/// Symmetry: r = (s_a d_a, s_b d_b, d_c), d = u - S0, maps it onto the reference
/// tetrahedron V0 = (0,0,0), V1 = (2,0,0) (secondary), V2 = (1,1,-1), V3 = (1,1,1) (primary)
/// = { r_y >= |r_z|, r_y <= r_x <= 2 - r_y }. The map is a signed axis permutation, so
/// gradients map by the same signed permutation and Hessians by conjugation.
///
/// Domain: tetrahedra near the boundary of the primary box lack a secondary vertex, so BCC
/// interpolators clamp points to the secondary points' box [1, 2R-3]^3 (h/2 inside the
/// primary box), which the complete tetrahedra cover.
#pragma once

#include <cmath>

#include "kernels/reconstruction/interpolator.h"
#include "kernels/reconstruction/lattice_field_view.h"

namespace sdf {

/// Reference-tetrahedron vertex k, coordinate i.
SDF_CPU_GPU constexpr int bcc_reference_vertex(int k, int i) {
    constexpr int v[4][3] = {{0, 0, 0}, {2, 0, 0}, {1, 1, -1}, {1, 1, 1}};
    return v[k][i];
}

struct BccTetrahedron {
    Int3 centre{};          ///< S0, the secondary point at the centre of the primary cube
    int axis[3]{0, 1, 2};   ///< reference axis i is lattice axis axis[i]
    int sign[3]{1, 1, 1};   ///< and is flipped by sign[i]

    /// Lattice coordinates of reference vertex k.
    SDF_CPU_GPU Int3 vertex(int k) const {
        Int3 c = centre;
        for (int i = 0; i < 3; ++i) c[axis[i]] += sign[i] * bcc_reference_vertex(k, i);
        return c;
    }
    /// Lattice coordinates -> reference coordinates.
    template <typename T>
    SDF_CPU_GPU Vec3<T> to_reference(const Vec3<T>& u) const {
        Vec3<T> r;
        for (int i = 0; i < 3; ++i) r[i] = T(sign[i]) * (u[axis[i]] - T(centre[axis[i]]));
        return r;
    }
    /// A lattice-frame vector (a gradient) in the reference frame.
    template <typename T>
    SDF_CPU_GPU Vec3<T> vector_to_reference(const Vec3<T>& g) const {
        return {T(sign[0]) * g[axis[0]], T(sign[1]) * g[axis[1]], T(sign[2]) * g[axis[2]]};
    }
    /// A reference-frame vector back in the lattice frame.
    template <typename T>
    SDF_CPU_GPU Vec3<T> vector_from_reference(const Vec3<T>& r) const {
        Vec3<T> g;
        for (int i = 0; i < 3; ++i) g[axis[i]] = T(sign[i]) * r[i];
        return g;
    }
};

/// Barycentric coordinates in the reference tetrahedron, and their constant gradients.
template <typename T>
SDF_CPU_GPU void bcc_reference_barycentrics(const Vec3<T>& r, T lambda[4]) {
    lambda[0] = T(1) - (r.x + r.y) / 2;
    lambda[1] = (r.x - r.y) / 2;
    lambda[2] = (r.y - r.z) / 2;
    lambda[3] = (r.y + r.z) / 2;
}

template <typename T>
SDF_CPU_GPU Vec3<T> bcc_reference_barycentric_gradient(int k) {
    const T h = T(0.5);
    return k == 0 ? Vec3<T>(-h, -h, 0) : k == 1 ? Vec3<T>(h, -h, 0) : k == 2 ? Vec3<T>(0, h, -h) : Vec3<T>(0, h, h);
}

/// World box covered by complete tetrahedra: the secondary points' box.
template <typename T>
SDF_CPU_GPU DomainBox<T> bcc_domain(const LatticeFieldView<T>& v) {
    const Int3 r = v.lattice.resolution;
    return {v.to_world(Vec3<T>(T(1))), v.to_world(Vec3<T>(T(2 * r.x - 3), T(2 * r.y - 3), T(2 * r.z - 3)))};
}

/// Clamps lattice coordinates u into the BCC domain; returns whether u was inside.
template <typename T>
SDF_CPU_GPU bool clamp_to_bcc_domain(const Lattice& l, Vec3<T>& u) {
    const Int3 r = l.resolution;
    return clamp_to_box(u, Vec3<T>(T(1)), Vec3<T>(T(2 * r.x - 3), T(2 * r.y - 3), T(2 * r.z - 3)));
}

/// The tetrahedron holding lattice coordinates u (u inside the BCC domain; R >= 3).
template <typename T>
SDF_CPU_GPU BccTetrahedron bcc_tetrahedron_at(const Lattice& l, const Vec3<T>& u) {
    BccTetrahedron tet;
    Vec3<T> d;
    for (int i = 0; i < 3; ++i) {
        int cube = 2 * int(std::floor(u[i] / 2));  // lower corner of the primary cube
        const int top = 2 * l.resolution[i] - 4;
        cube = cube > top ? top : (cube < 0 ? 0 : cube);
        tet.centre[i] = cube + 1;
        d[i] = u[i] - T(tet.centre[i]);
    }
    // Pyramid: the axis of the largest |d|
    const T ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    const int a = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    const int b0 = (a + 1) % 3, c0 = (a + 2) % 3;
    // Piece of the pyramid: the larger of the two other components
    const bool swap = std::abs(d[c0]) > std::abs(d[b0]);
    const int b = swap ? c0 : b0, c = swap ? b0 : c0;
    tet.axis[0] = a; tet.axis[1] = b; tet.axis[2] = c;
    // Sign of the pyramid axis; at the cube centre itself, point into the lattice
    const bool room_above = tet.centre[a] + 2 <= 2 * l.resolution[a] - 3;
    tet.sign[0] = d[a] > T(0) ? 1 : (d[a] < T(0) ? -1 : (room_above ? 1 : -1));
    tet.sign[1] = d[b] >= T(0) ? 1 : -1;
    tet.sign[2] = 1;
    return tet;
}

}  // namespace sdf
