// Continuity of the BCC splines across tetrahedron faces: both pieces that share a face are
// evaluated at the same point of that face (evaluate_in, so no point location decides) and
// the value and gradient jumps are measured, on random data and on smooth data.
//   bcc_linear:   value jumps 0 (to rounding), gradient jumps O(1).
//   bcc_cubic:    value jumps nonzero: the face-centre coefficient of eq. 4-9 depends on the
//                 opposite vertex (the thesis's C1 claim of 4.1.2 does not hold).
//   bcc_cubic_c0: value jumps 0 (to rounding), gradient jumps nonzero (C0, not C1).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>

#include "reconstruction_test_util.h"

namespace sdf {
namespace {

struct Jumps {
    double value_max = 0, value_rms = 0, gradient_max = 0, gradient_rms = 0;
    int faces = 0;
};

std::set<int64_t> vertex_ids(const Lattice& l, const BccTetrahedron& t) {
    std::set<int64_t> s;
    for (int k = 0; k < 4; ++k) s.insert(l.index_of_coords(t.vertex(k)));
    return s;
}

/// Jumps of interpolator I across `faces` random interior faces.
template <typename I>
Jumps measure_jumps(const LatticeFieldView<double>& v, int faces, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u01(0, 1);
    const Int3 r = v.lattice.resolution;
    Jumps j;
    double vsq = 0, gsq = 0;
    for (int attempt = 0; j.faces < faces && attempt < 4 * faces; ++attempt) {
        const Vec3d u(2 + u01(rng) * (2 * r.x - 6), 2 + u01(rng) * (2 * r.y - 6), 2 + u01(rng) * (2 * r.z - 6));
        const BccTetrahedron t1 = bcc_tetrahedron_at(v.lattice, u);
        // A random point on the face opposite vertex l, and the outward normal
        const int l = int(u01(rng) * 4) % 4;
        double lam[4], sum = 0;
        for (int k = 0; k < 4; ++k) sum += (lam[k] = k == l ? 0.0 : 0.05 + u01(rng));
        Vec3d q(0.0);
        for (int k = 0; k < 4; ++k) {
            const Int3 c = t1.vertex(k);
            q += Vec3d(c.x, c.y, c.z) * (lam[k] / sum);
        }
        const Vec3d outward = -normalize_or_zero(t1.vector_from_reference(bcc_reference_barycentric_gradient<double>(l)));
        const BccTetrahedron t2 = bcc_tetrahedron_at(v.lattice, q + outward * 1e-6);
        EXPECT_NE(vertex_ids(v.lattice, t1), vertex_ids(v.lattice, t2));
        if (vertex_ids(v.lattice, t1) == vertex_ids(v.lattice, t2)) continue;
        const ReconstructedSample<double> a = I::evaluate_in(v, t1, q), b = I::evaluate_in(v, t2, q);
        const double dv = std::abs(a.value - b.value), dg = length(a.gradient - b.gradient);
        j.value_max = std::max(j.value_max, dv);
        j.gradient_max = std::max(j.gradient_max, dg);
        vsq += dv * dv;
        gsq += dg * dg;
        ++j.faces;
    }
    j.value_rms = std::sqrt(vsq / faces);
    j.gradient_rms = std::sqrt(gsq / faces);
    return j;
}

/// Random values, derivatives and second derivatives in [-1, 1] on a BCC lattice.
HermiteData<double> random_bcc_data(InterpolatorKind kind) {
    std::mt19937 rng(51);
    std::uniform_real_distribution<double> u(-1, 1);
    HermiteData<double> d;
    d.lattice = test::make_lattice(LatticeType::BCC, {8, 8, 8}, 1.0, {0, 0, 0});
    d.higher_stride = kBccFullStride;
    for (int64_t i = 0; i < d.lattice.num_points(); ++i) {
        d.values.push_back(u(rng));
        d.first.emplace_back(u(rng), u(rng), u(rng));
        for (int k = 0; k < kBccFullStride; ++k) d.higher.push_back(u(rng));
    }
    d.faces = to_face_table<double>(kind == kind_of<BccCubicC0>() ? bcc_cubic_c0_face_weights()
                                                                         : bcc_cubic_face_weights());
    return d;
}

void print(const char* what, const Jumps& j) {
    std::printf("%-44s faces %5d  value jump max %.3e rms %.3e  gradient jump max %.3e rms %.3e\n", what, j.faces,
                j.value_max, j.value_rms, j.gradient_max, j.gradient_rms);
}

TEST(Continuity, RandomData) {
    const HermiteData<double> faithful = random_bcc_data(kind_of<BccCubic>());
    const HermiteData<double> c0 = random_bcc_data(kind_of<BccCubicC0>());
    const Jumps jl = measure_jumps<BccLinear>(faithful.view(), 4000, 1);
    const Jumps jf = measure_jumps<BccCubic>(faithful.view(), 4000, 1);
    const Jumps jc = measure_jumps<BccCubicC0>(c0.view(), 4000, 1);
    print("random data, bcc_linear", jl);
    print("random data, bcc_cubic", jf);
    print("random data, bcc_cubic_c0", jc);
    EXPECT_LT(jl.value_max, 1e-13);
    EXPECT_GT(jf.value_max, 1e-2);  // not continuous
    EXPECT_GT(jf.value_rms, 1e-3);
    EXPECT_LT(jc.value_max, 1e-12);  // continuous to rounding
    EXPECT_GT(jc.gradient_max, 1e-2);  // but not C1
}

TEST(Continuity, SmoothData) {
    // TrigFunction (scale 2) on the unit cube, at two spacings; jumps in the function's units
    for (int intervals : {8, 16}) {
        for (DerivativeSource src : {DerivativeSource::True, DerivativeSource::FiniteDifferences}) {
            const Lattice l = lattice_spanning(LatticeType::BCC, {intervals + 1, intervals + 1, intervals + 1},
                                               Vec3d(0.0), Vec3d(1.0));
            const SampledField field = sample_analytic_field(l, TrigFunction<double>{2.0});
            const Reconstruction faithful(field, {kind_of<BccCubic>(), src});
            const Reconstruction c0(field, {kind_of<BccCubicC0>(), src});
            const Jumps jf = measure_jumps<BccCubic>(faithful.view(), 3000, 2);
            const Jumps jc = measure_jumps<BccCubicC0>(c0.view(), 3000, 2);
            const std::string tag = "h = 1/" + std::to_string(intervals) + ", " + derivative_source_name(src) + ", ";
            print((tag + "bcc_cubic").c_str(), jf);
            print((tag + "bcc_cubic_c0").c_str(), jc);
            EXPECT_GT(jf.value_max, 1e-9);
            EXPECT_LT(jc.value_max, 1e-13);
        }
    }
}

}  // namespace
}  // namespace sdf
