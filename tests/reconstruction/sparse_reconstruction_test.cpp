// The reconstruction of a sparse narrow band straight from its blocks
// (core/reconstruction/sparse_reconstruction.h, issue 35): at every point, the value,
// gradient and inside flag of Reconstruction on the densified band, bit for bit, for every
// filter that reconstructs locally and every derivative source it takes (CC and BCC, a band
// with tiles of both signs and one with mixed blocks across a hole); points inside the band,
// near its edge, far outside it, on and beyond the lattice's edge (clamped), and NaN. Its
// memory grows with the band: a 4096^3 band, whose dense field the memory check refuses,
// reconstructs as a small dense lattice holding the same values does.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/reconstruction/reconstruction.h"
#include "core/reconstruction/sparse_reconstruction.h"
#include "core/sampling/sparse_band_cells.h"
#include "core/sampling/sparse_band_window.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "harness/resources/memory_budget.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"

namespace sdf {
namespace {

bool same_sample(const ReconstructedSample<double>& a, const ReconstructedSample<double>& b) {
    return std::memcmp(&a.value, &b.value, sizeof(double)) == 0 && std::memcmp(&a.gradient, &b.gradient, sizeof(Vec3d)) == 0 &&
           a.inside == b.inside;
}

std::string text(const ReconstructedSample<double>& s) {
    char t[160];
    std::snprintf(t, sizeof t, "%.17g (%.17g %.17g %.17g)%s", s.value, s.gradient.x, s.gradient.y, s.gradient.z,
                  s.inside ? "" : " outside");
    return t;
}

SparseBandField sample_band(const PreparedMesh& mesh, const Lattice& lattice, double width, SignMode sign) {
    SamplerOptions o;
    o.sign = sign;
    o.progress = false;
    return make_cpu_bvh_sampler(o)->bind(std::make_shared<const PreparedMesh>(mesh))->sample_band_sparse(lattice, width);
}

/// Query points: uniform in the lattice's box, around the band's points (inside the band,
/// across its edge, just beyond it), on and beyond the lattice's edge, and NaN.
std::vector<Vec3d> query_points(const SparseBandField& band, uint32_t seed) {
    std::mt19937 rng(seed);
    const Lattice& l = band.lattice;
    const Vec3d lo = l.domain_min(), hi = l.domain_max(), e = hi - lo;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<Vec3d> p;
    for (int i = 0; i < 1500; ++i) p.push_back(lo + Vec3d(unit(rng) * e.x, unit(rng) * e.y, unit(rng) * e.z));
    // Around the band's points: offsets up to 2 spacings reach well past its edge.
    std::vector<Vec3d> in_band;
    for (size_t a = 0; a < band.active.size(); ++a)
        for (int local = 0; local < kBandBlockPoints; local += 7)
            if (band.closest_triangle[a * kBandBlockPoints + size_t(local)] != kOutsideBandTriangle &&
                band.layout().storage_index(band.active[a], local) >= 0)
                in_band.push_back(l.position_of_coords(band.layout().point_coords(band.active[a], local)));
    std::uniform_int_distribution<size_t> pick(0, in_band.size() - 1);
    std::uniform_real_distribution<double> offset(-2.0 * l.spacing, 2.0 * l.spacing);
    for (int i = 0; i < 1500; ++i) p.push_back(in_band[pick(rng)] + Vec3d(offset(rng), offset(rng), offset(rng)));
    for (int i = 0; i < 100; ++i) p.push_back(in_band[pick(rng)]);  // lattice points themselves
    // The lattice's corners and faces exactly, and points beyond them (clamped).
    for (int c = 0; c < 8; ++c) p.push_back({c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z});
    for (int i = 0; i < 200; ++i) {
        Vec3d q = lo + Vec3d(unit(rng) * e.x, unit(rng) * e.y, unit(rng) * e.z);
        const int axis = i % 3;
        q[axis] = i % 2 ? hi[axis] + unit(rng) * 0.3 * e[axis] : lo[axis] - unit(rng) * 0.3 * e[axis];
        if (i % 5 == 0) q[axis] = i % 2 ? hi[axis] : lo[axis];
        p.push_back(q);
    }
    p.push_back({std::numeric_limits<double>::quiet_NaN(), lo.y, lo.z});
    p.push_back({hi.x * 1e30, -1e300, std::numeric_limits<double>::infinity()});
    return p;
}

struct BandCase {
    std::string name;
    SparseBandField band;
};

std::vector<BandCase> band_cases() {
    const PreparedMesh torus = prepare_mesh(make_torus(1.0, 0.35, 32, 16));
    const PreparedMesh bowl = test::open_bowl();
    std::vector<BandCase> cases;
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        const Int3 res = type == LatticeType::CC ? Int3{44, 40, 37} : Int3{31, 29, 27};
        const Lattice lt = fit_lattice(type, {res.x, res.y, res.z}, torus.bounds(), 0.3);
        cases.push_back({std::string("torus ") + lattice_notation(lt), sample_band(torus, lt, 1.5 * lt.spacing, SignMode::Pseudonormal)});
        const Lattice lb = fit_lattice(type, {res.x, res.y, res.z}, bowl.bounds(), 0.5);
        cases.push_back({std::string("open bowl (winding) ") + lattice_notation(lb),
                         sample_band(bowl, lb, 1.0 * lb.spacing, SignMode::Winding)});
    }
    return cases;
}

TEST(SparseBandWindow, EqualsTheDensifiedBandsPoints) {
    for (const BandCase& c : band_cases()) {
        const SampledField dense = c.band.densify();
        const Lattice& l = c.band.lattice;
        for (const LatticeWindow w : {LatticeWindow{{0, 0, 0}, l.resolution}, LatticeWindow{{3, 9, 1}, {11, 2, 20}},
                                      LatticeWindow{{l.resolution.x - 5, 0, 7}, {5, 1, 9}}}) {
            const SampledField window = densify_window(c.band, w, true);
            const Lattice wl = window.lattice;
            ASSERT_EQ(window.size(), wl.num_points());
            for (int64_t i = 0; i < window.size(); ++i) {
                const Int3 k = wl.coords_of(i);
                const int64_t j = l.index_of_coords({k.x + 2 * w.first.x, k.y + 2 * w.first.y, k.z + 2 * w.first.z});
                ASSERT_GE(j, 0);
                ASSERT_EQ(window.distance[size_t(i)], dense.distance[size_t(j)]) << c.name << " point " << i;
                ASSERT_EQ(window.closest_triangle[size_t(i)], dense.closest_triangle[size_t(j)]) << c.name;
                ASSERT_EQ(std::memcmp(&window.gradient[size_t(i)], &dense.gradient[size_t(j)], sizeof(Vec3d)), 0) << c.name;
                EXPECT_NEAR(length(wl.position(i) - l.position(j)), 0.0, 1e-12);
            }
            EXPECT_TRUE(densify_window(c.band, w, false).gradient.empty());
        }
        EXPECT_THROW(densify_window(c.band, {{-1, 0, 0}, {2, 2, 2}}, true), std::invalid_argument);
        EXPECT_THROW(densify_window(c.band, {{0, 0, 0}, {l.resolution.x + 1, 2, 2}}, true), std::invalid_argument);
        EXPECT_THROW(densify_window(c.band, {{0, 0, 0}, {0, 2, 2}}, true), std::invalid_argument);
    }
}

// Every local filter, every derivative source, bit for bit, batched and one point at a time.
TEST(SparseReconstruction, EqualsTheDensifiedBandsReconstructionBitForBit) {
    int compared_filters = 0;
    for (const BandCase& c : band_cases()) {
        const SampledField dense = c.band.densify();
        const std::vector<Vec3d> points = query_points(c.band, 7);
        int outside_cells = 0, clamped = 0;
        for (const Vec3d& p : points) outside_cells += in_band_cells(c.band, p) ? 0 : 1;
        EXPECT_GT(outside_cells, 500) << c.name;
        for (int k = 0; k < kInterpolatorKinds; ++k) {
            const InterpolatorKind kind = InterpolatorKind(k);
            if (interpolator_lattice(kind) != c.band.lattice.type) continue;
            if (!reconstructs_locally(kind)) {
                ReconstructionSpec spec;
                spec.interpolator = kind;
                EXPECT_THROW(SparseReconstruction(c.band, spec, true), std::invalid_argument) << interpolator_name(kind);
                continue;
            }
            for (DerivativeSource source : valid_derivative_sources(kind)) {
                ReconstructionSpec spec;
                spec.interpolator = kind;
                spec.derivatives = source;
                const std::string what = c.name + " " + describe(spec);
                const Reconstruction full(dense, spec);
                const SparseReconstruction sparse(c.band, spec, true);
                const std::vector<ReconstructedSample<double>> want = full.evaluate(points, 2);
                const std::vector<ReconstructedSample<double>> got = sparse.evaluate(points, 2);
                ASSERT_EQ(got.size(), want.size());
                int wrong = 0;
                for (size_t i = 0; i < points.size(); ++i) {
                    clamped += want[i].inside ? 0 : 1;
                    if (!same_sample(got[i], want[i]) && ++wrong <= 3)
                        ADD_FAILURE() << what << ": point " << i << " (" << points[i].x << ", " << points[i].y << ", "
                                      << points[i].z << "): " << text(got[i]) << " vs dense " << text(want[i]);
                }
                for (size_t i = 0; i < points.size(); i += 37)
                    EXPECT_TRUE(same_sample(sparse.evaluate(points[i]), want[i])) << what << ": one point, " << i;
                const DomainBox<double> a = sparse.domain(), b = full.domain();
                EXPECT_TRUE(a.lo.x == b.lo.x && a.lo.y == b.lo.y && a.lo.z == b.lo.z && a.hi.x == b.hi.x && a.hi.y == b.hi.y &&
                            a.hi.z == b.hi.z)
                    << what;
                ++compared_filters;
                if (HasFailure()) return;
            }
        }
        EXPECT_GT(clamped, 100) << c.name;
    }
    EXPECT_GE(compared_filters, 2 * 4 + 2 * 10);  // two bands per lattice: 4 CC and 10 BCC filter/source pairs
}

// Without a gradient channel (a file read without one), "fd" is the default and "true" is refused, as on the dense field.
TEST(SparseReconstruction, WithoutGradientsAsTheDenseFieldWithout) {
    const BandCase c = band_cases()[1];
    SampledField dense = c.band.densify();
    dense.gradient.clear();
    const Reconstruction full(dense, "tricubic_lm", "");
    const SparseReconstruction sparse(c.band, "tricubic_lm", "", false);
    EXPECT_EQ(sparse.spec().derivatives, DerivativeSource::FiniteDifferences);
    const std::vector<Vec3d> points = query_points(c.band, 11);
    const auto want = full.evaluate(points), got = sparse.evaluate(points);
    for (size_t i = 0; i < points.size(); ++i) ASSERT_TRUE(same_sample(got[i], want[i])) << i;
    EXPECT_THROW(SparseReconstruction(c.band, "tricubic_lm", "true", false), std::invalid_argument);
}

/// A sphere of radius 10 about c as a band of width 3 on a lattice of spacing 1 at the
/// origin, only its blocks near the sphere filled in (the rest outside tiles, +W).
SparseBandField sphere_band(const Lattice& lattice, const Vec3d& c) {
    const double w = 3.0, radius = 10.0;
    SparseBandField band(lattice, w, Precision::Double);
    const BandLayout& layout = band.layout();
    const Int3 b0{int(c.x) / 8 - 3, int(c.y) / 8 - 3, int(c.z) / 8 - 3};
    for (int bz = b0.z; bz <= b0.z + 6; ++bz)
        for (int by = b0.y; by <= b0.y + 6; ++by)
            for (int bx = b0.x; bx <= b0.x + 6; ++bx) {
                const int64_t id = layout.block_id(0, {bx, by, bz});
                bool near = false, all_inside = true;
                for (int local = 0; local < kBandBlockPoints; ++local) {
                    const double d = length(lattice.position_of_coords(layout.point_coords(id, local)) - c) - radius;
                    near = near || std::abs(d) <= w;
                    all_inside = all_inside && d < -w;
                }
                if (!near) {
                    band.set_tile_inside(id, all_inside);
                    continue;
                }
                const size_t base = size_t(band.add_active(id)) * kBandBlockPoints;
                for (int local = 0; local < kBandBlockPoints; ++local) {
                    const Vec3d x = lattice.position_of_coords(layout.point_coords(id, local)) - c;
                    const double d = length(x) - radius;
                    if (std::abs(d) > w) continue;  // +-W below
                    band.distance.set(base + size_t(local), d);
                    band.gradient[base + size_t(local)] = x / length(x);
                    band.closest_triangle[base + size_t(local)] = 0;
                }
                for (int local = 0; local < kBandBlockPoints; ++local)
                    if (band.closest_triangle[base + size_t(local)] == kOutsideBandTriangle) {
                        const Vec3d x = lattice.position_of_coords(layout.point_coords(id, local)) - c;
                        band.distance.set(base + size_t(local), length(x) - radius < 0 ? -w : w);
                    }
            }
    band.mask_from_triangles();  // the band's points, as its triangles mark them
    return band;
}

// A 4096^3 band (1.5 TB dense; the memory check refuses it) reconstructs, and as a dense
// lattice of 48^3 holding the same values around the sphere does: the interpolators work in
// lattice units, so a lattice shifted by whole spacings gives the same bits.
TEST(SparseReconstruction, AHugeLatticesBandReconstructsWithTheBandsMemory) {
    Lattice huge;
    huge.type = LatticeType::CC;
    huge.spacing = 1.0;
    huge.origin = Vec3d(0.0);
    huge.resolution = {4096, 4096, 4096};
    const Vec3d centre{2000.25, 2001.5, 1999.75};
    const uint64_t dense_bytes = uint64_t(SparseBandField::dense_bytes(huge));
    EXPECT_THROW(require_host_memory({dense_bytes, "densifying the test band"}, "sparse_reconstruction_test"), std::runtime_error);
    const SparseBandField band = sphere_band(huge, centre);
    EXPECT_LT(band.memory_bytes(), size_t(64) << 20);
    EXPECT_GT(band.active.size(), 20u);

    // The same values on a small dense lattice: origin at a whole number of spacings.
    Lattice small = huge;
    small.resolution = {48, 48, 48};
    small.origin = Vec3d(1976.0, 1976.0, 1976.0);
    SampledField dense;
    dense.lattice = small;
    dense.precision = Precision::Double;
    dense.resize(small.num_points());
    const SampledField window = densify_window(band, {{1976, 1976, 1976}, {48, 48, 48}}, true);
    dense.distance = window.distance;
    dense.gradient = window.gradient;
    dense.closest_triangle = window.closest_triangle;

    std::mt19937 rng(3);
    std::uniform_real_distribution<double> dir(-1.0, 1.0), r(8.5, 11.5);
    std::vector<Vec3d> points;
    for (int i = 0; i < 400; ++i) {
        Vec3d d(dir(rng), dir(rng), dir(rng));
        if (length(d) < 0.1) continue;
        points.push_back(centre + d / length(d) * r(rng));
    }
    for (const char* name : {"trilinear", "tricubic_lm"}) {
        const SparseReconstruction sparse(band, name, "fd", true);
        const Reconstruction shifted(dense, name, "fd");
        const auto got = sparse.evaluate(points), want = shifted.evaluate(points);
        double worst = 0;
        for (size_t i = 0; i < points.size(); ++i) {
            ASSERT_EQ(got[i].value, want[i].value) << name << " point " << i;
            ASSERT_EQ(got[i].gradient.x, want[i].gradient.x) << name << " point " << i;
            ASSERT_EQ(got[i].gradient.z, want[i].gradient.z) << name << " point " << i;
            ASSERT_TRUE(got[i].inside);
            // And the sphere it samples (away from the band's +-W: within 1.5 of the surface).
            const double exact = length(points[i] - centre) - 10.0;
            if (std::abs(exact) < 1.5) worst = std::max(worst, std::abs(got[i].value - exact));
        }
        EXPECT_LT(worst, 0.06) << name;  // h^2-order errors of a sphere of radius 10 h
    }
    EXPECT_LT(peak_resident_bytes(), uint64_t(2) << 30);
}

}  // namespace
}  // namespace sdf
