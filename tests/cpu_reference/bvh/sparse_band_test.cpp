// The sparse narrow band (core/sampling/sparse_band.h, issue 35): densified, it equals the
// dense sampler's banded field (SamplerOptions::band_width) byte for byte, on meshes with
// holes (the winding sign changes across them, away from any triangle: mixed blocks),
// several shells, self-intersections, a solid (pseudonormal sign, one side per cell) and a
// pseudonormal sign forced on an open mesh (every outside point queried); CC and BCC, float
// and double, the CPU BVH and brute force. The layout's indexing covers every lattice point
// once, and sparsify() of a dense band densifies back to it. On solids the block kernel's
// search is bounded by the band and the points beyond it take their sides from their
// neighbours (kernels/lattice/band_sides.h): checked where whole blocks lie beyond the band
// (an icosahedron's triangle boxes reach far from it), on the torus and the dragon (where
// SDF_DATA_PATH has it), at widths from one spacing up, and switched off below one; and on a
// tetrahedron of slivers with exact ties, every side off the surface the winding number's.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <set>
#include <stdexcept>
#include <string>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/sampling/sparse_band.h"
#include "core/sampling/narrow_band.h"
#include "core/sampling/sparse_band_window.h"
#include "core/winding/winding_sign.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

SamplerOptions options(Precision precision, double band, SignMode sign) {
    SamplerOptions o;
    o.precision = precision;
    o.band_width = band;
    o.sign = sign;
    o.progress = false;
    return o;
}

template <typename V, typename A>
bool same_bytes(const std::vector<V, A>& a, const std::vector<V, A>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(V)) == 0);
}
bool same_bytes(const BandDistances& a, const BandDistances& b) { return a.same_bytes(b); }

/// The first differing point, for the message.
std::string first_difference(const SampledField& a, const SampledField& b) {
    for (int64_t i = 0; i < a.size() && i < b.size(); ++i)
        if (a.distance[size_t(i)] != b.distance[size_t(i)] || a.closest_triangle[size_t(i)] != b.closest_triangle[size_t(i)] ||
            std::memcmp(&a.gradient[size_t(i)], &b.gradient[size_t(i)], sizeof(Vec3d)) != 0)
            return "point " + std::to_string(i) + ": " + std::to_string(a.distance[size_t(i)]) + " (triangle " +
                   std::to_string(a.closest_triangle[size_t(i)]) + ") vs " + std::to_string(b.distance[size_t(i)]) +
                   " (triangle " + std::to_string(b.closest_triangle[size_t(i)]) + ")";
    return "sizes " + std::to_string(a.size()) + " vs " + std::to_string(b.size());
}

void expect_same_field(const SampledField& dense, const SampledField& densified, const std::string& what) {
    const bool same = same_bytes(dense.distance, densified.distance) && same_bytes(dense.gradient, densified.gradient) &&
                      same_bytes(dense.closest_triangle, densified.closest_triangle);
    EXPECT_TRUE(same) << what << ": " << (same ? "" : first_difference(dense, densified));
}

/// Expects `call` to throw an E whose message holds `text`; `unrefused` is the failure's message.
template <typename E, typename Call>
void expect_refused(const Call& call, const std::string& text, const std::string& unrefused) {
    try {
        call();
        ADD_FAILURE() << unrefused;
    } catch (const E& e) {
        EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
}

TriangleMesh joined(const std::vector<TriangleMesh>& parts, const std::string& name) {
    TriangleMesh m;
    m.name = name;
    m.source = "shape:" + name;
    for (const TriangleMesh& p : parts) {
        const int base = int(m.vertices.size());
        m.vertices.insert(m.vertices.end(), p.vertices.begin(), p.vertices.end());
        for (const Int3& t : p.triangles) m.triangles.push_back({t.x + base, t.y + base, t.z + base});
    }
    return m;
}

struct Case {
    std::string name;
    PreparedMesh mesh;
    SignMode sign;
};

std::vector<Case> cases() {
    std::vector<Case> out;
    out.push_back({"torus (solid, pseudonormal)", prepare_mesh(make_torus(1.0, 0.35, 32, 16)), SignMode::Pseudonormal});
    out.push_back({"open bowl (winding)", test::open_bowl(), SignMode::Winding});
    out.push_back({"open bowl (pseudonormal forced)", test::open_bowl(), SignMode::Pseudonormal});
    out.push_back({"nested and separate shells (winding)",
                   prepare_mesh(joined({make_icosphere(2, 1.0), make_icosphere(2, 0.45, {0.1, 0.0, 0.0}),
                                        make_icosphere(2, 0.4, {1.9, 0.3, 0.2})},
                                       "shells")),
                   SignMode::Winding});
    out.push_back({"overlapping spheres (self-intersecting, winding)",
                   prepare_mesh(joined({make_icosphere(2, 1.0), make_icosphere(2, 0.8, {0.7, 0.2, 0.1})}, "overlap")),
                   SignMode::Winding});
    out.push_back({"disjoint shells (pseudonormal forced)",
                   prepare_mesh(joined({make_icosphere(2, 1.0), make_icosphere(2, 0.4, {1.9, 0.3, 0.2})}, "two")),
                   SignMode::Pseudonormal});
    const std::string bunny = test::find_data_file("bunny-open.obj");
    if (!bunny.empty()) out.push_back({"bunny-open (winding)", prepare_mesh(load_mesh_file(bunny)), SignMode::Winding});
    return out;
}

TEST(SparseBandLayout, EveryLatticePointOnceAndCellsTile) {
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        Lattice lattice;
        lattice.type = type;
        lattice.origin = {-1.0, 0.5, 2.0};
        lattice.spacing = 0.25;
        lattice.resolution = {17, 9, 24};
        const BandLayout layout(lattice);
        std::vector<int> seen(size_t(lattice.num_points()), 0);
        for (int64_t id = 0; id < layout.block_count(); ++id)
            for (int local = 0; local < kBandBlockPoints; ++local) {
                const int64_t i = layout.storage_index(id, local);
                if (i < 0) continue;
                ++seen[size_t(i)];
                EXPECT_EQ(lattice.index_of_coords(layout.point_coords(id, local)), i);
            }
        for (int s : seen) ASSERT_EQ(s, 1) << lattice_type_name(type);
        EXPECT_EQ(layout.cosets(), type == LatticeType::BCC ? 2 : 1);
        EXPECT_EQ(layout.block_count(), type == LatticeType::BCC ? 3 * 2 * 3 + 2 * 1 * 3 : 3 * 2 * 3);
        Vec3d lo, hi;
        layout.cell_box(layout.block_id(0, {1, 0, 0}), lo, hi);
        EXPECT_EQ(lo.x, -1.0 + 8 * 0.25);
        EXPECT_EQ(hi.x, -1.0 + 16 * 0.25);
    }
}

TEST(SparseBand, DensifiedEqualsTheDenseBandByteForByte) {
    for (const Case& c : cases()) {
        const Lattice cc = fit_lattice(LatticeType::CC, {41, 38, 36}, c.mesh.bounds(), 0.4);
        const Lattice bcc = fit_lattice(LatticeType::BCC, {29, 27, 26}, c.mesh.bounds(), 0.4);
        for (Precision precision : {Precision::Float, Precision::Double})
            for (const Lattice& lattice : {cc, bcc})
                for (double spacings : {0.6, 3.0}) {
                    const double w = spacings * lattice.spacing;
                    const std::string what = c.name + " " + lattice_notation(lattice) + " " + precision_name(precision) +
                                             " w = " + std::to_string(spacings) + " h";
                    const SampledField dense =
                        make_cpu_bvh_sampler(options(precision, w, c.sign))->bind(share(c.mesh))->sample(lattice);
                    const SparseBandField sparse =
                        make_cpu_bvh_sampler(options(precision, 0, c.sign))->bind(share(c.mesh))->sample_band_sparse(lattice, w);
                    expect_same_field(dense, sparse.densify(), what + " cpu/bvh");
                    const SparseBandCounts counts = sparse.counts();
                    ASSERT_TRUE(sparse.sampler.band.has_value());
                    EXPECT_EQ(sparse.sampler.band->points_in_band, dense.sampler.band->points_in_band) << what;
                    EXPECT_EQ(counts.band_points, dense.sampler.band->points_in_band) << what;
                    EXPECT_GT(counts.tiles, 0) << what;
                    EXPECT_LT(counts.active_blocks, counts.blocks) << what;
                    EXPECT_EQ(sparse.sampler.backend, "cpu") << what;
                    // The dense band, sparsified, densifies back to itself.
                    expect_same_field(dense, SparseBandField::sparsify(dense, w).densify(), what + " sparsify");
                    if (precision == Precision::Float && spacings == 3.0) {
                        const SparseBandField brute = make_cpu_brute_force_sampler(options(precision, 0, c.sign))
                                                          ->bind(share(c.mesh))
                                                          ->sample_band_sparse(lattice, w);
                        expect_same_field(dense, brute.densify(), what + " cpu/brute_force");
                    }
                    if (HasFailure()) return;
                }
    }
}

/// Every padding point (beyond the lattice) of the band's active blocks holds +W, gradient 0
/// (when held) and kOutsideBandTriangle: the block kernels write into unfilled arrays.
/// Returns the points that do not; adds the padding points checked to `checked`.
int64_t bad_padding(const SparseBandField& band, int64_t& checked) {
    int64_t bad = 0;
    for (size_t a = 0; a < band.active.size(); ++a)
        for (int local = 0; local < kBandBlockPoints; ++local) {
            if (band.layout().storage_index(band.active[a], local) >= 0) continue;
            ++checked;
            const size_t v = a * kBandBlockPoints + size_t(local);
            const bool zero = !band.channels.gradient ||
                              (band.gradient[v].x == 0 && band.gradient[v].y == 0 && band.gradient[v].z == 0);
            const bool off_band = !band.in_band(a, local) &&
                                  (!band.channels.closest_triangle || band.closest_triangle[v] == kOutsideBandTriangle);
            if (!(band.distance[v] == band.width && off_band && zero)) ++bad;
        }
    return bad;
}

// A band sampled without its gradient channel: the same distances, closest triangles, tiles
// and mixed blocks, byte for byte, as with it (through the brick kernel and the point
// queries); no gradient held, and none densified.
TEST(SparseBand, WithoutTheGradientTheSameDistancesAndTriangles) {
    BandChannels slim_channels;
    slim_channels.gradient = false;
    int64_t padding = 0;
    for (const Case& c : cases()) {
        const Lattice cc = fit_lattice(LatticeType::CC, {41, 38, 36}, c.mesh.bounds(), 0.4);
        const Lattice bcc = fit_lattice(LatticeType::BCC, {29, 27, 26}, c.mesh.bounds(), 0.4);
        for (const Lattice& lattice : {cc, bcc}) {
            const double w = 2.0 * lattice.spacing;
            const std::string what = c.name + " " + lattice_notation(lattice);
            const auto bound = make_cpu_bvh_sampler(options(Precision::Float, 0, c.sign))->bind(share(c.mesh));
            const SparseBandField full = bound->sample_band_sparse(lattice, w);
            const SparseBandField slim = bound->sample_band_sparse(lattice, w, slim_channels);
            EXPECT_TRUE(full.channels.gradient) << what;
            EXPECT_EQ(full.gradient.size(), full.distance.size()) << what;
            EXPECT_FALSE(slim.channels.gradient) << what;
            EXPECT_TRUE(slim.gradient.empty()) << what;
            EXPECT_TRUE(same_bytes(full.active, slim.active)) << what;
            EXPECT_TRUE(same_bytes(full.distance, slim.distance)) << what;
            EXPECT_TRUE(same_bytes(full.closest_triangle, slim.closest_triangle)) << what;
            EXPECT_TRUE(same_bytes(full.mixed, slim.mixed)) << what;
            EXPECT_TRUE(same_bytes(full.mixed_inside, slim.mixed_inside)) << what;
            EXPECT_EQ(full.counts().inside_tiles, slim.counts().inside_tiles) << what;
            EXPECT_EQ(bad_padding(full, padding), 0) << what;
            EXPECT_EQ(bad_padding(slim, padding), 0) << what;
            EXPECT_LT(slim.memory_bytes(), full.memory_bytes()) << what;
            EXPECT_EQ(slim.sampler.details["sparse_band"]["channels"], nlohmann::json::array({"distance", "closest_triangle"}))
                << what;
            // Densified: the dense band's distances and triangles, no gradient.
            const SampledField dense =
                make_cpu_bvh_sampler(options(Precision::Float, w, c.sign))->bind(share(c.mesh))->sample(lattice);
            const SampledField densified = slim.densify();
            EXPECT_TRUE(densified.gradient.empty()) << what;
            EXPECT_TRUE(same_bytes(dense.distance, densified.distance)) << what;
            EXPECT_TRUE(same_bytes(dense.closest_triangle, densified.closest_triangle)) << what;
            EXPECT_TRUE(slim.densify_slab({3, 9}).gradient.empty()) << what;
            EXPECT_LT(SparseBandField::dense_bytes(lattice, slim_channels), SparseBandField::dense_bytes(lattice)) << what;
            // The dense band sparsified without its gradient: the same values.
            const SparseBandField sparsified = SparseBandField::sparsify(dense, w, slim_channels);
            EXPECT_TRUE(sparsified.gradient.empty()) << what;
            const SampledField back = sparsified.densify();
            EXPECT_TRUE(back.gradient.empty() && same_bytes(dense.distance, back.distance) &&
                        same_bytes(dense.closest_triangle, back.closest_triangle))
                << what;
            // Asking a band without gradients for them is refused, naming the caller's what.
            try {
                slim.require_channels(BandChannels{}, "the test's writer");
                ADD_FAILURE() << what << ": require_channels accepted a missing gradient";
            } catch (const std::invalid_argument& e) {
                EXPECT_NE(std::string(e.what()).find("the test's writer: the band holds no gradient"), std::string::npos)
                    << e.what();
            }
            EXPECT_NO_THROW(slim.require_channels(slim_channels, "x")) << what;
            EXPECT_NO_THROW(full.require_channels(BandChannels{}, "x")) << what;
            if (HasFailure()) return;
        }
        // Point queries (brute force has no block kernel): the same bytes too. A lattice
        // close around the mesh, so that active blocks reach past its far edges (padding).
        const Lattice lattice = fit_lattice(LatticeType::CC, {27, 26, 25}, c.mesh.bounds(), 0.05);
        const auto brute = make_cpu_brute_force_sampler(options(Precision::Float, 0, c.sign))->bind(share(c.mesh));
        const SparseBandField full = brute->sample_band_sparse(lattice, 2 * lattice.spacing);
        const SparseBandField slim = brute->sample_band_sparse(lattice, 2 * lattice.spacing, slim_channels);
        EXPECT_TRUE(slim.gradient.empty()) << c.name;
        EXPECT_TRUE(same_bytes(full.distance, slim.distance) && same_bytes(full.closest_triangle, slim.closest_triangle))
            << c.name << " brute force";
        EXPECT_EQ(bad_padding(slim, padding), 0) << c.name << " brute force";
        const SparseBandField bvh = make_cpu_bvh_sampler(options(Precision::Float, 0, c.sign))
                                        ->bind(share(c.mesh))
                                        ->sample_band_sparse(lattice, 2 * lattice.spacing, slim_channels);
        EXPECT_EQ(bad_padding(bvh, padding), 0) << c.name << " bvh";
        EXPECT_TRUE(same_bytes(bvh.distance, slim.distance) && same_bytes(bvh.closest_triangle, slim.closest_triangle))
            << c.name << " bvh against brute force";
    }
    EXPECT_GT(padding, 0) << "no active block reached the lattice's far edges";
    // A dense field without gradients cannot give a band with them.
    const PreparedMesh torus = prepare_mesh(make_torus(1.0, 0.35, 32, 16));
    const Lattice lattice = fit_lattice(LatticeType::CC, {20, 20, 20}, torus.bounds(), 0.3);
    SampledField dense = make_cpu_bvh_sampler(options(Precision::Float, 0, SignMode::Auto))->bind(share(torus))->sample(lattice);
    dense.gradient.clear();
    EXPECT_THROW(SparseBandField::sparsify(dense, 2 * lattice.spacing), std::invalid_argument);
    EXPECT_TRUE(SparseBandField::sparsify(dense, 2 * lattice.spacing, slim_channels).gradient.empty());
}

/// Whether a float32 band's distances are a double band's, each rounded once (float(d)).
bool rounded_from(const BandDistances& f32, const BandDistances& f64) {
    if (!f32.float32() || f64.float32() || f32.size() != f64.size()) return false;
    for (size_t i = 0; i < f32.size(); ++i) {
        const float want = float(f64[i]), got = float(f32[i]);
        if (std::memcmp(&want, &got, sizeof(float)) != 0) return false;
    }
    return true;
}

// A band held in float32 (for float32 outputs): every distance the double band's rounded once,
// everything else (blocks, band points, triangles, gradients, signs) the same bytes, through
// the brick kernel and the point queries, CC and BCC, both sign rules, both search precisions;
// densified, the dense band rounded; refused where double distances are asked.
TEST(SparseBand, Float32DistancesAreTheDoubleBandRoundedOnce) {
    BandChannels f32_channels;
    f32_channels.distance_type = BandDistanceType::Float32;
    for (const Case& c : cases()) {
        const Lattice cc = fit_lattice(LatticeType::CC, {37, 34, 33}, c.mesh.bounds(), 0.3);
        const Lattice bcc = fit_lattice(LatticeType::BCC, {27, 25, 24}, c.mesh.bounds(), 0.3);
        for (const Lattice& lattice : {cc, bcc})
            for (Precision precision : {Precision::Float, Precision::Double}) {
                const double w = 2.0 * lattice.spacing;
                const std::string what = c.name + " " + lattice_notation(lattice) + " " + precision_name(precision);
                for (int brute = 0; brute < 2; ++brute) {
                    const auto bound = (brute ? make_cpu_brute_force_sampler(options(precision, 0, c.sign))
                                              : make_cpu_bvh_sampler(options(precision, 0, c.sign)))
                                           ->bind(share(c.mesh));
                    const SparseBandField f64 = bound->sample_band_sparse(lattice, w);
                    const SparseBandField f32 = bound->sample_band_sparse(lattice, w, f32_channels);
                    const std::string how = what + (brute ? " brute force" : " bvh");
                    EXPECT_TRUE(rounded_from(f32.distance, f64.distance)) << how;
                    EXPECT_TRUE(same_bytes(f32.active, f64.active) && same_bytes(f32.gradient, f64.gradient) &&
                                same_bytes(f32.closest_triangle, f64.closest_triangle) &&
                                same_bytes(f32.band_mask, f64.band_mask) && same_bytes(f32.mixed, f64.mixed) &&
                                same_bytes(f32.mixed_inside, f64.mixed_inside) && same_bytes(f32.inside_tiles, f64.inside_tiles))
                        << how;
                    EXPECT_EQ(f64.memory_bytes() - f32.memory_bytes(), f64.distance.size() * sizeof(float)) << how;
                    // Densified: the dense band, every distance rounded once (the bytes a float32 file holds).
                    const SampledField dense = f64.densify(), densified = f32.densify();
                    bool rounded = dense.size() == densified.size();
                    for (int64_t i = 0; rounded && i < dense.size(); ++i)
                        rounded = double(float(dense.distance[size_t(i)])) == densified.distance[size_t(i)] &&
                                  std::signbit(dense.distance[size_t(i)]) == std::signbit(densified.distance[size_t(i)]);
                    EXPECT_TRUE(rounded) << how;
                    EXPECT_TRUE(same_bytes(dense.closest_triangle, densified.closest_triangle)) << how;
                    expect_refused<std::invalid_argument>([&] { f32.require_channels(BandChannels{}, "the test's reader"); },
                                                          "the test's reader: the band holds its distances in float32",
                                                          how + ": require_channels gave float32 distances to a reader of doubles");
                    EXPECT_NO_THROW(f32.require_channels(f32_channels, "x")) << how;
                    EXPECT_NO_THROW(f64.require_channels(f32_channels, "x")) << how;  // a float32 writer takes doubles
                    if (HasFailure()) return;
                }
            }
    }
}

/// The band's points by the rule of the dense band (narrow_band.h): the points of each active
/// block whose closest triangle is not kOutsideBandTriangle, padding excluded.
std::vector<BandPointMask> masks_from_triangles(const SparseBandField& band) {
    std::vector<BandPointMask> masks(band.active.size(), BandPointMask{});
    for (size_t a = 0; a < band.active.size(); ++a)
        for (int local = 0; local < kBandBlockPoints; ++local)
            if (band.layout().storage_index(band.active[a], local) >= 0 &&
                band.closest_triangle[a * kBandBlockPoints + size_t(local)] != kOutsideBandTriangle)
                set_mask_bit(masks[a], local);
    return masks;
}

bool same_masks(const std::vector<BandPointMask>& a, const DefaultInitVector<BandPointMask>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(BandPointMask)) == 0);
}

bool same_counts(const SparseBandCounts& a, const SparseBandCounts& b) {
    return a.blocks == b.blocks && a.active_blocks == b.active_blocks && a.mixed_blocks == b.mixed_blocks && a.tiles == b.tiles &&
           a.inside_tiles == b.inside_tiles && a.active_points == b.active_points && a.band_points == b.band_points;
}

// A band sampled without its closest triangles (with and without the gradient): the same
// distances (and gradients), tiles and mixed blocks byte for byte as the full band, and its
// band points, a bit per point, are the full band's points whose triangle marks them
// (through the brick kernel and the point queries). Densified it is the dense band without
// the closest-triangle channel; its slabs count the dense slabs' band points.
TEST(SparseBand, WithoutTheClosestTriangleTheSameValuesAndBandPoints) {
    BandChannels no_triangle, distance_only;
    no_triangle.closest_triangle = false;
    distance_only.gradient = false;
    distance_only.closest_triangle = false;
    int64_t padding = 0;
    for (const Case& c : cases()) {
        const Lattice cc = fit_lattice(LatticeType::CC, {41, 38, 36}, c.mesh.bounds(), 0.4);
        const Lattice bcc = fit_lattice(LatticeType::BCC, {29, 27, 26}, c.mesh.bounds(), 0.4);
        for (const Lattice& lattice : {cc, bcc}) {
            const double w = 2.0 * lattice.spacing;
            const auto bound = make_cpu_bvh_sampler(options(Precision::Float, 0, c.sign))->bind(share(c.mesh));
            const SparseBandField full = bound->sample_band_sparse(lattice, w);
            const std::vector<BandPointMask> truth = masks_from_triangles(full);
            EXPECT_TRUE(same_masks(truth, full.band_mask)) << c.name << " " << lattice_notation(lattice) << ": the full band";
            const SampledField dense =
                make_cpu_bvh_sampler(options(Precision::Float, w, c.sign))->bind(share(c.mesh))->sample(lattice);
            for (const BandChannels& channels : {no_triangle, distance_only}) {
                const std::string what = c.name + " " + lattice_notation(lattice) + (channels.gradient ? " no triangle" : " distance only");
                const SparseBandField lean = bound->sample_band_sparse(lattice, w, channels);
                EXPECT_FALSE(lean.channels.closest_triangle) << what;
                EXPECT_TRUE(lean.closest_triangle.empty()) << what;
                EXPECT_EQ(lean.gradient.empty(), !channels.gradient) << what;
                EXPECT_TRUE(same_bytes(full.active, lean.active)) << what;
                EXPECT_TRUE(same_bytes(full.distance, lean.distance)) << what;
                if (channels.gradient) {
                    EXPECT_TRUE(same_bytes(full.gradient, lean.gradient)) << what;
                }
                EXPECT_TRUE(same_masks(truth, lean.band_mask)) << what;
                EXPECT_TRUE(same_bytes(full.mixed, lean.mixed)) << what;
                EXPECT_TRUE(same_bytes(full.mixed_inside, lean.mixed_inside)) << what;
                EXPECT_TRUE(same_counts(full.counts(), lean.counts())) << what;
                EXPECT_EQ(lean.counts().band_points, count_narrow_band(dense).in_band) << what;
                EXPECT_EQ(bad_padding(lean, padding), 0) << what;
                EXPECT_LT(lean.memory_bytes(), full.memory_bytes()) << what;
                EXPECT_EQ(lean.sampler.details["sparse_band"]["channels"], channel_names(channels)) << what;
                // Densified: the dense band's distances (and gradients), no triangle channel.
                const SampledField densified = lean.densify();
                EXPECT_TRUE(densified.closest_triangle.empty()) << what;
                EXPECT_TRUE(same_bytes(dense.distance, densified.distance)) << what;
                if (channels.gradient) {
                    EXPECT_TRUE(same_bytes(dense.gradient, densified.gradient)) << what;
                } else {
                    EXPECT_TRUE(densified.gradient.empty()) << what;
                }
                // A slab's counts from the mask: the dense slab's (count_narrow_band of its triangles).
                NarrowBandCounts slab_counts;
                const SampledField slab = lean.densify_slab({3, 9}, &slab_counts);
                const NarrowBandCounts dense_slab = count_narrow_band(full.densify_slab({3, 9}));
                EXPECT_TRUE(slab.closest_triangle.empty()) << what;
                EXPECT_EQ(slab_counts.in_band, dense_slab.in_band) << what;
                EXPECT_EQ(slab_counts.outside, dense_slab.outside) << what;
                EXPECT_LT(SparseBandField::dense_bytes(lattice, channels), SparseBandField::dense_bytes(lattice)) << what;
                // Sparsified without the channel: the band sparsified with it (whose active
                // blocks are those holding band points, fewer than the sampler's), less the triangles.
                const SparseBandField sparsified = SparseBandField::sparsify(dense, w, channels);
                const SparseBandField sparsified_full = SparseBandField::sparsify(dense, w);
                EXPECT_TRUE(sparsified.closest_triangle.empty()) << what;
                EXPECT_TRUE(same_masks(masks_from_triangles(sparsified_full), sparsified.band_mask) &&
                            same_bytes(sparsified.distance, sparsified_full.distance) &&
                            same_bytes(sparsified.active, sparsified_full.active))
                    << what;
                EXPECT_EQ(sparsified.counts().band_points, lean.counts().band_points) << what;
                // Asking it for triangles is refused, naming the caller's what.
                BandChannels wanted = channels;
                wanted.closest_triangle = true;
                expect_refused<std::invalid_argument>([&] { lean.require_channels(wanted, "the test's writer"); },
                                                      "the test's writer: the band holds no closest triangle",
                                                      what + ": require_channels accepted a missing closest triangle");
                EXPECT_NO_THROW(lean.require_channels(channels, "x")) << what;
            }
            if (HasFailure()) return;
        }
        // Point queries (brute force has no block kernel): the same band points too, padding
        // included (a lattice close around the mesh).
        const Lattice lattice = fit_lattice(LatticeType::CC, {27, 26, 25}, c.mesh.bounds(), 0.05);
        const auto brute = make_cpu_brute_force_sampler(options(Precision::Float, 0, c.sign))->bind(share(c.mesh));
        const SparseBandField full = brute->sample_band_sparse(lattice, 2 * lattice.spacing);
        const SparseBandField lean = brute->sample_band_sparse(lattice, 2 * lattice.spacing, distance_only);
        EXPECT_TRUE(lean.closest_triangle.empty() && lean.gradient.empty()) << c.name;
        EXPECT_TRUE(same_masks(masks_from_triangles(full), full.band_mask)) << c.name << " brute force";
        EXPECT_TRUE(same_masks(masks_from_triangles(full), lean.band_mask) && same_bytes(full.distance, lean.distance))
            << c.name << " brute force";
        EXPECT_EQ(bad_padding(lean, padding), 0) << c.name << " brute force";
    }
    EXPECT_GT(padding, 0) << "no active block reached the lattice's far edges";
}

TEST(SparseBand, SweepAndFloodEqualTheDenseBand) {
    const std::vector<test::BandSolid> cases = test::band_solids(1.0);
    int64_t flooded = 0, searched_blocks = 0;
    for (const test::BandSolid& c : cases) {
        ASSERT_EQ(choose_sign_mode(c.mesh.report(), SignMode::Auto).mode, SignMode::Pseudonormal) << c.name << " is a solid";
        const Lattice cc = fit_lattice(LatticeType::CC, c.cc, c.mesh.bounds(), 0.4);
        const Lattice bcc = fit_lattice(LatticeType::BCC, c.bcc, c.mesh.bounds(), 0.4);
        for (Precision precision : {Precision::Float, Precision::Double})
            for (const Lattice& lattice : {cc, bcc})
                for (double spacings : {0.9, 1.0, 1.7, 3.0}) {
                    const double w = spacings * lattice.spacing;
                    const std::string what = c.name + " " + lattice_notation(lattice) + " " + precision_name(precision) +
                                             " W = " + std::to_string(spacings) + " h";
                    const SampledField dense = make_cpu_bvh_sampler(options(precision, w, SignMode::Auto))->bind(share(c.mesh))->sample(lattice);
                    const SparseBandField sparse =
                        make_cpu_bvh_sampler(options(precision, 0, SignMode::Auto))->bind(share(c.mesh))->sample_band_sparse(lattice, w);
                    ASSERT_TRUE(sparse.sampler.details.contains("band_blocks_on_host")) << what;
                    const nlohmann::json& d = sparse.sampler.details["band_blocks_on_host"];
                    EXPECT_EQ(d["bounded_search"].get<bool>(), spacings >= 1.0) << what;
                    EXPECT_EQ(d["nearest"], spacings >= 1.0 ? "triangle_sweep" : "search") << what;
                    if (spacings >= 1.0) {
                        EXPECT_GT(d["points_flooded"].get<int64_t>(), 0) << what;
                    }
                    // The outside's cells signed from their neighbours (no query) from one spacing up.
                    const nlohmann::json& cells = sparse.sampler.details["sparse_band"];
                    if (spacings >= 1.0) {
                        EXPECT_EQ(cells["uniform_cells_beside_the_band"], cells["uniform_cells"]) << what;
                    } else {
                        EXPECT_EQ(cells["uniform_cells_beside_the_band"].get<int64_t>(), 0) << what;
                    }
                    flooded += d["points_flooded"].get<int64_t>();
                    searched_blocks += d["blocks_signed_by_a_search"].get<int64_t>();
                    expect_same_field(dense, sparse.densify(), what);
                    if (HasFailure()) return;
                }
    }
    // Whole blocks beyond the band (test::lattice_cutting_the_box).
    const PreparedMesh box = prepare_mesh(make_box({1.0, 1.0, 1.0}));
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC})
        for (Precision precision : {Precision::Float, Precision::Double}) {
            const Lattice lattice = test::lattice_cutting_the_box(type);
            const double w = 3 * lattice.spacing;
            const std::string what = "box cut by " + lattice_notation(lattice) + " " + precision_name(precision);
            const SampledField dense = make_cpu_bvh_sampler(options(precision, w, SignMode::Auto))->bind(share(box))->sample(lattice);
            const SparseBandField sparse =
                make_cpu_bvh_sampler(options(precision, 0, SignMode::Auto))->bind(share(box))->sample_band_sparse(lattice, w);
            const nlohmann::json& d = sparse.sampler.details["band_blocks_on_host"];
            searched_blocks += d["blocks_signed_by_a_search"].get<int64_t>();
            expect_same_field(dense, sparse.densify(), what);
        }
    EXPECT_GT(flooded, 0);
    EXPECT_GT(searched_blocks, 0) << "no block was all beyond the band: the search for its side went untested";
}

// Slivers of every kind (down to those searched by their edges alone) and exact ties: lattice
// points on the fans' shared vertices and edges, where several triangles are equally near.
TEST(SparseBand, SliversAndTiesEqualTheDenseBand) {
    int64_t flooded = 0;
    test::for_each_fan_case({1.0, 3.0}, [&](const test::FanCase& c) {
        const SampledField dense = make_cpu_bvh_sampler(options(c.precision, c.width, SignMode::Auto))->bind(share(c.mesh))->sample(c.lattice);
        const SampledField winding =
            make_cpu_bvh_sampler(options(c.precision, c.width, SignMode::Winding))->bind(share(c.mesh))->sample(c.lattice);
        EXPECT_EQ(test::sides_off_the_winding_number(dense, winding), 0) << c.name << ": signs off the winding number's";
        const SparseBandField sparse =
            make_cpu_bvh_sampler(options(c.precision, 0, SignMode::Auto))->bind(share(c.mesh))->sample_band_sparse(c.lattice, c.width);
        flooded += sparse.sampler.details["band_blocks_on_host"]["points_flooded"].get<int64_t>();
        expect_same_field(dense, sparse.densify(), c.name);
    });
    EXPECT_GT(flooded, 0);
}

// The fan down to 2^-45: slivers within the double search's rounding of the sharp edge A C,
// where a point's nearest triangle may be a sliver whose edge pseudonormal gives the fan's
// side alone. Preparation counts them (MeshReport::slivers_within_rounding), so `auto` takes
// the winding sign: every side off the surface is the exact winding number's, dense and
// sparse alike. Forced, the pseudonormal sign still gets the wrong side there (the reason
// for the rule), and the sparse band then samples every point as the dense band does.
TEST(SparseBand, SliversWithinRoundingTakeTheWindingSign) {
    const PreparedMesh fan = prepare_mesh(test::fanned_tetrahedron({0, 0, 0}, 45));
    ASSERT_GT(fan.report().slivers_within_rounding, 0);
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        const Lattice lattice = test::lattice_through_the_fan(type);
        const double w = 3 * lattice.spacing;
        const std::string what = "the fan down to 2^-45, " + lattice_notation(lattice);
        const SampledField winding = make_cpu_bvh_sampler(options(Precision::Float, w, SignMode::Winding))->bind(share(fan))->sample(lattice);
        const auto automatic = make_cpu_bvh_sampler(options(Precision::Float, 0, SignMode::Auto))->bind(share(fan));
        EXPECT_EQ(automatic->sign().mode, SignMode::Winding) << what;
        const SampledField dense = make_cpu_bvh_sampler(options(Precision::Float, w, SignMode::Auto))->bind(share(fan))->sample(lattice);
        EXPECT_EQ(test::sides_off_the_winding_number(dense, winding), 0) << what;
        expect_same_field(dense, automatic->sample_band_sparse(lattice, w).densify(), what + ", auto");
        const SampledField forced =
            make_cpu_bvh_sampler(options(Precision::Float, w, SignMode::Pseudonormal))->bind(share(fan))->sample(lattice);
        if (type == LatticeType::BCC) {
            EXPECT_GT(test::sides_off_the_winding_number(forced, winding), 0) << what << ": the pseudonormal sign was right";
        }
        expect_same_field(
            forced,
            make_cpu_bvh_sampler(options(Precision::Float, 0, SignMode::Pseudonormal))->bind(share(fan))->sample_band_sparse(lattice, w).densify(),
            what + ", pseudonormal forced");
    }
}

// Across the bowl's opening the winding number passes 1/2 far from any triangle: there the
// sides are stored per point, and they are the dense path's.
TEST(SparseBand, HolesGiveMixedBlocksWithTheDenseSides) {
    const PreparedMesh bowl = test::open_bowl();
    const Lattice lattice = fit_lattice(LatticeType::CC, {96, 96, 96}, bowl.bounds(), 0.6);
    const double w = 1.0 * lattice.spacing;
    const SampledField dense = make_cpu_bvh_sampler(options(Precision::Float, w, SignMode::Winding))->bind(share(bowl))->sample(lattice);
    const SparseBandField sparse =
        make_cpu_bvh_sampler(options(Precision::Float, 0, SignMode::Winding))->bind(share(bowl))->sample_band_sparse(lattice, w);
    expect_same_field(dense, sparse.densify(), "bowl 96^3");
    const SparseBandCounts counts = sparse.counts();
    EXPECT_GT(counts.mixed_blocks, 0);
    EXPECT_GT(counts.inside_tiles, 0);
    EXPECT_EQ(sparse.sampler.details["sparse_band"]["outside_rule"], "winding number bound (Biot-Savart)");
    EXPECT_LT(sparse.memory_bytes(), size_t(SparseBandField::dense_bytes(lattice)));
}

// Slabs of the sparse band (sdf-sample writes the field file slab by slab from it) equal the
// dense sampler's slabs, in their compact order.
TEST(SparseBand, SlabsEqualTheDenseSlabs) {
    const PreparedMesh bowl = test::open_bowl();
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        const Lattice lattice = fit_lattice(type, {37, 35, 33}, bowl.bounds(), 0.5);
        const double w = 1.5 * lattice.spacing;
        const auto dense = make_cpu_bvh_sampler(options(Precision::Float, w, SignMode::Winding))->bind(share(bowl));
        const SparseBandField sparse =
            make_cpu_bvh_sampler(options(Precision::Float, 0, SignMode::Winding))->bind(share(bowl))->sample_band_sparse(lattice, w);
        for (const LatticeSlab slab : {LatticeSlab{0, 5}, LatticeSlab{5, 17}, LatticeSlab{17, 32}, LatticeSlab{32, 33}})
            expect_same_field(dense->sample_slab(lattice, slab), sparse.densify_slab(slab),
                              std::string(lattice_type_name(type)) + " slab " + std::to_string(slab.z_begin));
        EXPECT_THROW(sparse.densify_slab({3, 3}), std::invalid_argument);
        EXPECT_THROW(sparse.densify_slab({0, 34}), std::invalid_argument);
    }
}

TEST(SparseBand, RefusesToDensifyPastTheLimitAndBadWidths) {
    const PreparedMesh torus = prepare_mesh(make_torus(1.0, 0.35, 32, 16));
    const Lattice lattice = fit_lattice(LatticeType::CC, {20, 20, 20}, torus.bounds(), 0.3);
    const auto bound = make_cpu_bvh_sampler(options(Precision::Float, 0, SignMode::Auto))->bind(share(torus));
    const SparseBandField sparse = bound->sample_band_sparse(lattice, 2 * lattice.spacing);
    EXPECT_THROW(sparse.densify(1000), std::length_error);
    EXPECT_THROW(bound->sample_band_sparse(lattice, 0.0), std::invalid_argument);
    EXPECT_THROW(bound->sample_band_sparse(lattice, -1.0), std::invalid_argument);
}

// A sparse band's lattice may be larger than any dense one (max_lattice_points): 8192^3
// (2^39 points, 2^30 blocks) around a torus that spans about a hundred of its spacings. Its
// windows densified equal the dense banded sampler's field of the same points byte for byte,
// near the surface and at the lattice's corner; the band's memory is checked before it is
// allocated (its bitsets, then its active blocks' channels).
TEST(SparseBand, LatticesBeyondTheDenseLimitAreSampledWithTheirMemoryChecked) {
    const PreparedMesh torus = prepare_mesh(make_torus(1.0, 0.35, 32, 16));
    const Int3 r{8192, 8192, 8192};
    try {
        fit_lattice(LatticeType::CC, r, torus.bounds(), 40.0);
        ADD_FAILURE() << "a dense 8192^3 lattice was not refused";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("a sparse narrow band may have up to 2^42"), std::string::npos) << e.what();
    }
    EXPECT_THROW(fit_lattice(LatticeType::CC, {16385, 16384, 16384}, torus.bounds(), 40.0, LatticeStorage::SparseBand),
                 std::invalid_argument);
    const Lattice lattice = fit_lattice(LatticeType::CC, r, torus.bounds(), 40.0, LatticeStorage::SparseBand);
    const double w = 2 * lattice.spacing;
    const auto sparse_sampler = make_cpu_bvh_sampler(options(Precision::Float, 0, SignMode::Auto))->bind(share(torus));
    const SparseBandField band = sparse_sampler->sample_band_sparse(lattice, w);
    const SparseBandCounts c = band.counts();
    EXPECT_EQ(c.blocks, int64_t(1) << 30);
    EXPECT_GT(c.band_points, 10000);
    EXPECT_EQ(c.tiles + c.active_blocks + c.mixed_blocks, c.blocks);
    // The torus spans the centre's 100 x 100 x 26 points; a window around it, and the corner.
    // Each point against the point query at its position in the lattice (a window's own
    // lattice rounds its positions differently): a band point holds the query's bits, any
    // other point +-W on the query's side, beyond W.
    int64_t compared = 0, in_band = 0, wrong = 0;
    for (const LatticeWindow& window : {LatticeWindow{{4096 - 60, 4096 - 60, 4096 - 18}, {120, 120, 36}},
                                        LatticeWindow{{0, 0, 0}, {9, 9, 9}}}) {
        ASSERT_TRUE(window.fits(lattice));
        const SampledField f = densify_window(band, window, true);
        std::vector<Vec3d> points;
        for (int k = 0; k < window.resolution.z; ++k)
            for (int j = 0; j < window.resolution.y; ++j)
                for (int i = 0; i < window.resolution.x; ++i)
                    points.push_back(lattice.position_of_coords(  // units of h/2
                        Int3{2 * (window.first.x + i), 2 * (window.first.y + j), 2 * (window.first.z + k)}));
        ASSERT_EQ(int64_t(points.size()), f.size());
        const std::vector<PointSample> q = sparse_sampler->query(points);
        for (size_t p = 0; p < q.size(); ++p, ++compared) {
            const bool band_point = f.closest_triangle[p] != kOutsideBandTriangle;
            in_band += band_point;
            const bool same = band_point ? f.distance[p] == q[p].distance && f.closest_triangle[p] == q[p].triangle &&
                                               std::memcmp(&f.gradient[p], &q[p].gradient, sizeof(Vec3d)) == 0
                                         : outside_band(q[p].distance, w) &&
                                               f.distance[p] == (std::signbit(q[p].distance) ? -w : w);
            if (!same && wrong++ < 5)
                ADD_FAILURE() << "point " << p << " of the window at " << window.first.x << ": " << f.distance[p]
                              << " against the query's " << q[p].distance;
        }
    }
    EXPECT_EQ(wrong, 0);
    EXPECT_GT(in_band, 10000);
    EXPECT_EQ(compared, 120 * 120 * 36 + 9 * 9 * 9);
    // Memory checked before it is allocated: the two bitsets (2 x 128 MiB), then the channels
    // of the active blocks of a lattice the torus fills.
    setenv("SDF_MEMORY_AVAILABLE", "100000000", 1);
    try {
        sparse_sampler->sample_band_sparse(lattice, w);
        ADD_FAILURE() << "100 MB held 256 MiB of bitsets";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("the sparse band of 8192x8192x8192 (its per-block bitsets) needs 256 MiB"),
                  std::string::npos)
            << e.what();
    }
    setenv("SDF_MEMORY_AVAILABLE", "1000000000", 1);
    const Lattice filled = fit_lattice(LatticeType::CC, r, torus.bounds(), 0.05, LatticeStorage::SparseBand);
    try {
        sparse_sampler->sample_band_sparse(filled, 2 * filled.spacing);
        ADD_FAILURE() << "1 GB held the active blocks of a torus filling 8192^3";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("active blocks of 512 points, 36 bytes a point"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("available to this process"), std::string::npos) << e.what();
    }
    unsetenv("SDF_MEMORY_AVAILABLE");
}

}  // namespace
}  // namespace sdf
