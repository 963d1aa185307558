// Smoothness of the spline filters across their knot planes, measured: both polynomial
// pieces that share a face are evaluated (with their analytic value, gradient and Hessian)
// at the same random point of that face, on random coefficients in [-1, 1]:
//   bcc_box_quintic: pieces per Delaunay tetrahedron; value, gradient and Hessian jumps at
//     rounding level (C2).
//   cc_bspline3: pieces per cell; the same across cell faces (C2).
//   bcc_box_linear: value jumps at rounding level across tetrahedron faces, gradient jumps
//     O(1) (C0 only); measured just off the face on both sides (its kernel is a closed form,
//     not a sum of pieces), so the value jump is bounded by the step times the gradient.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>

#include "box_spline_test_util.h"

namespace sdf {
namespace {

struct Jumps {
    double value = 0, gradient = 0, hessian = 0;
    int faces = 0;
    void add(const SplineJet<double>& a, const SplineJet<double>& b) {
        value = std::max(value, std::abs(a.value - b.value));
        gradient = std::max(gradient, length(a.gradient - b.gradient));
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                hessian = std::max(hessian, std::abs(hessian_entry(a.hessian, i, j) - hessian_entry(b.hessian, i, j)));
        ++faces;
    }
};

void print(const char* what, const Jumps& j) {
    std::printf("%-34s faces %5d  max jump: value %.2e  gradient %.2e  Hessian %.2e\n", what, j.faces, j.value,
                j.gradient, j.hessian);
}

std::vector<double> random_values(const Lattice& l, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<double> v(size_t(l.num_points()));
    for (double& x : v) x = u(rng);
    return v;
}

/// A random point on a random face of the tetrahedron holding a random u, the tetrahedron,
/// and the one across that face.
struct FacePoint {
    Vec3d q;
    BccTetrahedron inside, across;
};

FacePoint random_bcc_face(const Lattice& l, std::mt19937& rng) {
    std::uniform_real_distribution<double> u01(0, 1);
    const Int3 r = l.resolution;
    const Vec3d u(2 + u01(rng) * (2 * r.x - 6), 2 + u01(rng) * (2 * r.y - 6), 2 + u01(rng) * (2 * r.z - 6));
    FacePoint f;
    f.inside = bcc_tetrahedron_at(l, u);
    const int opposite = int(u01(rng) * 4) % 4;
    double lam[4], sum = 0;
    for (int k = 0; k < 4; ++k) sum += (lam[k] = k == opposite ? 0.0 : 0.05 + u01(rng));
    f.q = Vec3d(0.0);
    for (int k = 0; k < 4; ++k) {
        const Int3 c = f.inside.vertex(k);
        f.q += Vec3d(c.x, c.y, c.z) * (lam[k] / sum);
    }
    const Vec3d outward =
        -normalize_or_zero(f.inside.vector_from_reference(bcc_reference_barycentric_gradient<double>(opposite)));
    f.across = bcc_tetrahedron_at(l, f.q + outward * 1e-6);
    return f;
}

bool same_tetrahedron(const BccTetrahedron& a, const BccTetrahedron& b) {
    std::set<std::tuple<int, int, int>> sa, sb;
    for (int k = 0; k < 4; ++k) {
        sa.insert({a.vertex(k).x, a.vertex(k).y, a.vertex(k).z});
        sb.insert({b.vertex(k).x, b.vertex(k).y, b.vertex(k).z});
    }
    return sa == sb;
}

template <typename I>
Jumps quintic_jumps(const HermiteData<double>& d, int faces, unsigned seed) {
    std::mt19937 rng(seed);
    Jumps j;
    while (j.faces < faces) {
        const FacePoint f = random_bcc_face(d.lattice, rng);
        EXPECT_FALSE(same_tetrahedron(f.inside, f.across));
        j.add(I::jet_in(d.view(), f.inside, f.q, true), I::jet_in(d.view(), f.across, f.q, true));
    }
    return j;
}

TEST(BoxSplineContinuity, QuinticIsC2AcrossTetrahedronFaces) {
    const Lattice l = test::make_lattice(LatticeType::BCC, {8, 8, 8}, 1.0, Vec3d(0.0));
    const std::vector<double> values = random_values(l, 60);
    // Unit spacing and data in [-1, 1]: the jumps are in the data's units
    const Jumps a = quintic_jumps<BccBoxQuinticApprox>(test::spline_data_from_values<BccBoxQuinticApprox>(l, values), 4000, 61);
    const Jumps b = quintic_jumps<BccBoxQuintic>(test::spline_data_from_values<BccBoxQuintic>(l, values), 4000, 62);
    print("bcc_box_quintic_approx, random c", a);
    print("bcc_box_quintic, random f", b);
    for (const Jumps& j : {a, b}) {
        EXPECT_LT(j.value, 1e-14);
        EXPECT_LT(j.gradient, 1e-13);
        EXPECT_LT(j.hessian, 1e-12);
    }
}

TEST(BoxSplineContinuity, CubicBsplineIsC2AcrossCellFaces) {
    const Lattice l = test::make_lattice(LatticeType::CC, {10, 10, 10}, 1.0, Vec3d(0.0));
    const HermiteData<double> d = test::spline_data_from_values<CcBspline3>(l, random_values(l, 63));
    std::mt19937 rng(64);
    std::uniform_real_distribution<double> u01(0, 1);
    Jumps j;
    for (int n = 0; n < 3000; ++n) {
        // A random point on the face x_a = i + 1 between cells i and i + 1
        const int a = n % 3;
        Int3 corner{1 + int(u01(rng) * 6), 1 + int(u01(rng) * 6), 1 + int(u01(rng) * 6)};
        Vec3d t(u01(rng), u01(rng), u01(rng));
        t[a] = 1.0;
        Int3 next = corner;
        next[a] += 1;
        Vec3d t_next = t;
        t_next[a] = 0.0;
        j.add(CcBspline3::jet_in(d.view(), corner, t, true), CcBspline3::jet_in(d.view(), next, t_next, true));
    }
    print("cc_bspline3, random f", j);
    EXPECT_LT(j.value, 1e-14);
    EXPECT_LT(j.gradient, 1e-13);
    EXPECT_LT(j.hessian, 1e-12);
}

TEST(BoxSplineContinuity, LinearIsC0Only) {
    const Lattice l = test::make_lattice(LatticeType::BCC, {8, 8, 8}, 1.0, Vec3d(0.0));
    const HermiteData<double> d = test::spline_data_from_values<BccBoxLinear>(l, random_values(l, 65));
    std::mt19937 rng(66);
    const double step = 1e-9;
    Jumps j;
    while (j.faces < 4000) {
        const FacePoint f = random_bcc_face(l, rng);
        // Just off the face on each side, along the line between the two tetrahedra's centroids
        Vec3d c1(0.0), c2(0.0);
        for (int k = 0; k < 4; ++k) {
            c1 += Vec3d(f.inside.vertex(k).x, f.inside.vertex(k).y, f.inside.vertex(k).z) * 0.25;
            c2 += Vec3d(f.across.vertex(k).x, f.across.vertex(k).y, f.across.vertex(k).z) * 0.25;
        }
        const Vec3d dir = normalize_or_zero(c2 - c1);
        const auto a = BccBoxLinear::evaluate(d.view(), d.view().to_world(f.q - dir * step));
        const auto b = BccBoxLinear::evaluate(d.view(), d.view().to_world(f.q + dir * step));
        j.add({a.value, a.gradient, {}}, {b.value, b.gradient, {}});
    }
    print("bcc_box_linear, random f (1e-9 off)", j);
    EXPECT_LT(j.value, 1e-8);  // <= 2 step |gradient|, gradients are O(1)
    EXPECT_GT(j.gradient, 1e-1);  // not C1
}

}  // namespace
}  // namespace sdf
