/// @file bcc_cubic.h
/// @brief The thesis's cubic Hermite spline on the BCC lattice (section 4.1.1, eqs. 4-1 to
/// 4-9): per Delaunay tetrahedron a cubic that interpolates f and grad f at the 4 vertices
/// (16 constraints) and whose 4 remaining degrees of freedom minimise the squared error of
/// fxy, fxz, fyz at the vertices (eq. 4-3).
///
/// Representation: the cubic in Bernstein-Bezier form on the tetrahedron, p = sum_|a|=3
/// c_a 3!/a! lambda^a. The vertex data fix the 4 vertex coefficients, c_3i = f_i, and the 12
/// edge coefficients, c_2i+j = f_i + grad f_i . (v_j - v_i) / 3; the 4 face-centre
/// coefficients c_i+j+k are exactly the null space of the constraint matrix M of eq. 4-5,
/// and are linear in the vertex data. Their weights were solved once with Eigen for the
/// reference tetrahedron (eq. 4-9, core/reconstruction/bcc_cubic_tables.h) and
/// come in LatticeFieldView::bcc_faces; every tetrahedron reuses them through the symmetry
/// of bcc_tetrahedron.h, since eq. 4-3 is invariant under signed axis permutations.
///
/// The spline reproduces every cubic when given exact derivatives (thesis 4.1.2), so its
/// order is 4. It is NOT continuous across faces in general: a face's restriction depends on
/// its face-centre coefficient, which eq. 4-9 makes depend on the opposite vertex too
/// (docs/reconstruction.md measures the jumps). bcc_cubic_c0.h is the continuous variant.
#pragma once

#include "kernels/reconstruction/bcc_tetrahedron.h"

namespace sdf {

/// Vertex data in the reference frame: f, the gradient and the second derivatives (pure
/// ones only when the view stores them), per lattice unit h/2.
template <typename T>
SDF_CPU_GPU void bcc_reference_data(const LatticeFieldView<T>& v, const BccTetrahedron& tet, T data[4][kBccData]) {
    for (int k = 0; k < 4; ++k) {
        const int64_t index = bcc_index(v.lattice, tet.vertex(k));
        const Vec3<T> g = tet.vector_to_reference(v.first[index]);
        const T* h = v.higher + index * v.higher_stride;
        data[k][kDf] = v.values[index];
        data[k][kDx] = g.x; data[k][kDy] = g.y; data[k][kDz] = g.z;
        // Reference pair (i, j) is lattice pair (axis[i], axis[j]); slot xy/xz/yz = a + b - 1
        const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
        for (int m = 0; m < 3; ++m) {
            const int i = pairs[m][0], j = pairs[m][1];
            data[k][kDxy + m] = T(tet.sign[i] * tet.sign[j]) * h[tet.axis[i] + tet.axis[j] - 1];
        }
        for (int i = 0; i < 3; ++i)
            data[k][kDxx + i] = v.higher_stride >= kBccFullStride ? h[kBccDxx + tet.axis[i]] : T(0);
    }
}

/// Bernstein-Bezier coefficients of the cubic on the reference tetrahedron.
template <typename T>
struct BccCubicNet {
    T vertex[4];   ///< c_{3e_i} = f_i
    T edge[4][4];  ///< c_{2e_i + e_j}, i != j
    T face[4];     ///< c_{e_i + e_j + e_k}, the face opposite vertex l
};

template <typename T>
SDF_CPU_GPU BccCubicNet<T> bcc_cubic_net(const T data[4][kBccData], const BccFaceTable<T>& table) {
    BccCubicNet<T> net;
    for (int i = 0; i < 4; ++i) {
        net.vertex[i] = data[i][kDf];
        for (int j = 0; j < 4; ++j) {
            T step = T(0);  // grad f_i . (v_j - v_i)
            for (int a = 0; a < 3; ++a)
                step += data[i][kDx + a] * T(bcc_reference_vertex(j, a) - bcc_reference_vertex(i, a));
            net.edge[i][j] = data[i][kDf] + step * (T(1) / T(3));
        }
    }
    // Face centres: linear in all vertex data through the precomputed table
    for (int l = 0; l < 4; ++l) net.face[l] = T(0);
    for (int k = 0; k < 4; ++k)
        for (int m = 0; m < kBccData; ++m)
            for (int l = 0; l < 4; ++l) net.face[l] += table.w[k][m][l] * data[k][m];
    return net;
}

/// Value and reference-frame gradient of the Bernstein-Bezier cubic at reference point r.
template <typename T>
SDF_CPU_GPU ReconstructedSample<T> evaluate_bcc_cubic_net(const BccCubicNet<T>& net, const Vec3<T>& r) {
    T lam[4];
    bcc_reference_barycentrics(r, lam);
    ReconstructedSample<T> s;
    for (int i = 0; i < 4; ++i) {
        // p and dp/dlambda_i of the homogeneous form
        T dp = T(3) * net.vertex[i] * lam[i] * lam[i];
        s.value += net.vertex[i] * lam[i] * lam[i] * lam[i];
        for (int j = 0; j < 4; ++j) {
            if (j == i) continue;
            s.value += T(3) * net.edge[i][j] * lam[i] * lam[i] * lam[j];
            dp += T(6) * net.edge[i][j] * lam[i] * lam[j] + T(3) * net.edge[j][i] * lam[j] * lam[j];
        }
        for (int l = 0; l < 4; ++l) {
            if (l == i) continue;
            T others = T(6) * net.face[l];  // times the two lambdas other than l and i
            for (int m = 0; m < 4; ++m)
                if (m != l && m != i) others *= lam[m];
            dp += others;
        }
        s.gradient += bcc_reference_barycentric_gradient<T>(i) * dp;
    }
    for (int l = 0; l < 4; ++l) {
        T bubble = T(6) * net.face[l];
        for (int m = 0; m < 4; ++m)
            if (m != l) bubble *= lam[m];
        s.value += bubble;
    }
    return s;
}

/// The cubic piece of tetrahedron `tet` at lattice coordinates u (extended beyond the
/// tetrahedron when u lies outside it); world-space gradient.
template <typename T>
SDF_CPU_GPU ReconstructedSample<T> bcc_cubic_evaluate_in(const LatticeFieldView<T>& v, const BccTetrahedron& tet,
                                                         const Vec3<T>& u) {
    T data[4][kBccData];
    bcc_reference_data(v, tet, data);
    ReconstructedSample<T> s = evaluate_bcc_cubic_net(bcc_cubic_net(data, v.bcc_faces), tet.to_reference(u));
    s.gradient = tet.vector_from_reference(s.gradient) * v.inv_unit;
    return s;
}

template <typename T>
SDF_CPU_GPU ReconstructedSample<T> bcc_cubic_evaluate(const LatticeFieldView<T>& v, const Vec3<T>& p) {
    Vec3<T> u = v.to_lattice(p);
    const bool inside = clamp_to_bcc_domain(v.lattice, u);
    ReconstructedSample<T> s = bcc_cubic_evaluate_in(v, bcc_tetrahedron_at(v.lattice, u), u);
    s.inside = inside;
    return s;
}

/// The faithful thesis spline: face centres from eq. 4-9 (view.bcc_faces must hold the
/// table of bcc_cubic_tables.h's bcc_cubic_face_table()).
struct BccCubic {
    SDF_CPU_GPU static constexpr const char* name() { return "bcc_cubic"; }
    SDF_CPU_GPU static constexpr int radius() { return 1; }
    SDF_CPU_GPU static constexpr int order() { return 4; }
    SDF_CPU_GPU static constexpr bool interpolating() { return true; }
    SDF_CPU_GPU static constexpr LatticeType lattice_type() { return LatticeType::BCC; }
    SDF_CPU_GPU static constexpr bool uses_first() { return true; }
    SDF_CPU_GPU static constexpr int higher_stride() { return kBccMixedStride; }
    SDF_CPU_GPU static constexpr PointData point_data() { return PointData::BccCubicJet; }
    SDF_CPU_GPU static constexpr int min_resolution() { return 4; }

    template <typename T>
    SDF_CPU_GPU static DomainBox<T> domain(const LatticeFieldView<T>& v) { return bcc_domain(v); }
    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate_in(const LatticeFieldView<T>& v, const BccTetrahedron& tet,
                                                          const Vec3<T>& u) {
        return bcc_cubic_evaluate_in(v, tet, u);
    }
    template <typename T>
    SDF_CPU_GPU static ReconstructedSample<T> evaluate(const LatticeFieldView<T>& v, const Vec3<T>& p) {
        return bcc_cubic_evaluate(v, p);
    }
};

}  // namespace sdf
