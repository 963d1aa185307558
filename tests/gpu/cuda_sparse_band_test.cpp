// The sparse narrow band on the CUDA samplers (issue 35): densified, it equals the CPU BVH's
// dense banded field byte for byte (and the CUDA BVH's own dense band), on a solid
// (pseudonormal sign), an open bowl (winding sign: mixed blocks across its opening; and the
// pseudonormal sign forced on it: no brick skip), shells
// and self-intersecting spheres; CC and BCC, float and double; bunny-open where
// SDF_DATA_PATH has it. The CUDA BVH's warp and candidates kernels sample the active blocks
// in device memory (also in batches of a few blocks); its brick kernel and the brute force
// through point queries. On solids the warp kernel sweeps the triangles instead of searching
// and the points beyond the band take their sides from their neighbours (the flood): checked
// on solids whose triangles' boxes reach far from them (an icosahedron: whole blocks without a
// band point), the torus and the dragon, at widths from one spacing up, and off below one; and
// on a tetrahedron of slivers with exact ties (SliversAndTies...).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/sampling/sparse_band.h"
#include "core/winding/winding_sign.h"
#include "harness/sampling/sampler_table.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

SamplerOptions options(const std::string& backend, const std::string& method, Precision precision, double band, SignMode sign) {
    SamplerOptions o;
    o.backend = backend;
    o.method = method;
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

bool same_field(const SampledField& a, const SampledField& b) {
    return same_bytes(a.distance, b.distance) && same_bytes(a.gradient, b.gradient) &&
           same_bytes(a.closest_triangle, b.closest_triangle);
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

TEST(CudaSparseBand, DensifiedEqualsTheCpuDenseBand) {
    struct Case {
        std::string name;
        PreparedMesh mesh;
        SignMode sign;
    };
    std::vector<Case> cases;
    cases.push_back({"torus", prepare_mesh(make_torus(1.0, 0.35, 32, 16)), SignMode::Pseudonormal});
    cases.push_back({"open bowl", test::open_bowl(), SignMode::Winding});
    cases.push_back({"shells", prepare_mesh(joined({make_icosphere(2, 1.0), make_icosphere(2, 0.45, {0.1, 0.0, 0.0}),
                                                    make_icosphere(2, 0.4, {1.9, 0.3, 0.2})}, "shells")),
                     SignMode::Winding});
    cases.push_back({"overlap", prepare_mesh(joined({make_icosphere(2, 1.0), make_icosphere(2, 0.8, {0.7, 0.2, 0.1})}, "overlap")),
                     SignMode::Winding});
    const std::string bunny = test::find_data_file("bunny-open.obj");
    if (!bunny.empty()) cases.push_back({"bunny-open", prepare_mesh(load_mesh_file(bunny)), SignMode::Winding});
    // The pseudonormal sign forced on an open mesh: no brick skipped, every point searched.
    cases.push_back({"open bowl (pseudonormal)", test::open_bowl(), SignMode::Pseudonormal});
    for (const Case& c : cases) {
        const Lattice cc = fit_lattice(LatticeType::CC, {61, 58, 56}, c.mesh.bounds(), 0.4);
        const Lattice bcc = fit_lattice(LatticeType::BCC, {41, 39, 37}, c.mesh.bounds(), 0.4);
        for (Precision precision : {Precision::Float, Precision::Double})
            for (const Lattice& lattice : {cc, bcc}) {
                const double w = 2.5 * lattice.spacing;
                const std::string what = c.name + " " + lattice_notation(lattice) + " " + precision_name(precision);
                const SampledField cpu_dense = make_sampler(options("cpu", "bvh", precision, w, c.sign))->bind(share(c.mesh))->sample(lattice);
                const SampledField gpu_dense = make_sampler(options("cuda", "bvh", precision, w, c.sign))->bind(share(c.mesh))->sample(lattice);
                EXPECT_TRUE(same_field(cpu_dense, gpu_dense)) << what << ": the dense bands differ";
                // bvh warp and candidates: the active blocks in device memory (bvh_band_blocks.cu),
                // also in batches of 3 blocks; bvh brick and brute force: point queries.
                struct Run {
                    const char* method;
                    const char* kernel;
                    int64_t max_points_per_piece;
                    bool on_device;
                };
                for (const Run& run : {Run{"bvh", "warp", 0, true}, Run{"bvh", "candidates", 0, true},
                                       Run{"bvh", "warp", 3 * 512, true}, Run{"bvh", "candidates", 3 * 512 + 100, true},
                                       Run{"bvh", "brick", 0, false}, Run{"brute_force", "", 0, false}}) {
                    if (std::string(run.method) == "brute_force" && precision == Precision::Double) continue;
                    SamplerOptions o = options("cuda", run.method, precision, 0, c.sign);
                    o.kernel = run.kernel;
                    o.max_points_per_piece = run.max_points_per_piece;
                    const SparseBandField sparse = make_sampler(o)->bind(share(c.mesh))->sample_band_sparse(lattice, w);
                    const std::string which = what + " cuda/" + run.method + "/" + run.kernel + " piece " +
                                              std::to_string(run.max_points_per_piece);
                    EXPECT_EQ(sparse.sampler.backend, "cuda") << which;
                    EXPECT_EQ(sparse.sampler.details.contains("band_blocks_on_device"), run.on_device) << which;
                    if (run.on_device) {
                        const nlohmann::json& d = sparse.sampler.details["band_blocks_on_device"];
                        EXPECT_EQ(d["blocks"].get<int64_t>(), int64_t(sparse.active.size())) << which;
                        if (run.max_points_per_piece > 0) {
                            EXPECT_EQ(d["blocks_per_batch"].get<int64_t>(), 3) << which;
                        }
                        EXPECT_GT(sparse.timings.kernel, 0.0) << which;
                        EXPECT_LE(sparse.timings.kernel, sparse.timings.total) << which;
                        // A solid's bounded band takes the triangle sweep (no search, no
                        // certificate); every other band the certified search.
                        const bool swept = d["bounded_search"].get<bool>();
                        EXPECT_EQ(d["nearest"], swept ? "triangle_sweep" : "search") << which;
                        if (precision == Precision::Float && !swept) {
                            EXPECT_GT(sparse.timings.certified_points, 0) << which;
                        }
                    }
                    EXPECT_TRUE(same_field(cpu_dense, sparse.densify())) << which;
                    if (precision == Precision::Float) {
                        // Without the gradient channel (not downloaded): the same distances and
                        // triangles, padding included, in arrays the kernels wrote unfilled.
                        BandChannels slim_channels;
                        slim_channels.gradient = false;
                        const SparseBandField slim =
                            make_sampler(o)->bind(share(c.mesh))->sample_band_sparse(lattice, w, slim_channels);
                        EXPECT_TRUE(slim.gradient.empty()) << which;
                        EXPECT_TRUE(same_bytes(sparse.distance, slim.distance)) << which << ": without the gradient";
                        EXPECT_TRUE(same_bytes(sparse.closest_triangle, slim.closest_triangle)) << which << ": without the gradient";
                        // The band's points (the device's mask, mark_band_points) are the points
                        // whose triangle marks them; with the distance alone (neither gradient nor
                        // triangles downloaded) the same mask and distances.
                        std::vector<BandPointMask> truth(sparse.active.size(), BandPointMask{});
                        for (size_t a = 0; a < sparse.active.size(); ++a)
                            for (int local = 0; local < kBandBlockPoints; ++local)
                                if (sparse.layout().storage_index(sparse.active[a], local) >= 0 &&
                                    sparse.closest_triangle[a * kBandBlockPoints + size_t(local)] != kOutsideBandTriangle)
                                    set_mask_bit(truth[a], local);
                        const auto same_masks = [&](const SparseBandField& b) {
                            return b.band_mask.size() == truth.size() &&
                                   (truth.empty() || std::memcmp(b.band_mask.data(), truth.data(), truth.size() * 64) == 0);
                        };
                        EXPECT_TRUE(same_masks(sparse)) << which << ": the band's mask";
                        BandChannels lean_channels;
                        lean_channels.gradient = false;
                        lean_channels.closest_triangle = false;
                        const SparseBandField lean =
                            make_sampler(o)->bind(share(c.mesh))->sample_band_sparse(lattice, w, lean_channels);
                        EXPECT_TRUE(lean.gradient.empty() && lean.closest_triangle.empty()) << which;
                        EXPECT_TRUE(same_bytes(sparse.distance, lean.distance)) << which << ": the distance alone";
                        EXPECT_TRUE(same_masks(lean)) << which << ": the distance alone, its mask";
                        EXPECT_EQ(lean.counts().band_points, sparse.counts().band_points) << which;
                        // Held in float32 (sdf-sample's float32 outputs; rounded on the device): each
                        // distance the double band's rounded once, padding included; the same mask.
                        BandChannels f32_channels = lean_channels;
                        f32_channels.distance_type = BandDistanceType::Float32;
                        const SparseBandField f32 =
                            make_sampler(o)->bind(share(c.mesh))->sample_band_sparse(lattice, w, f32_channels);
                        bool rounded = f32.distance.float32() && f32.distance.size() == sparse.distance.size();
                        for (size_t i = 0; rounded && i < f32.distance.size(); ++i) {
                            const float want = float(sparse.distance[i]), got = float(f32.distance[i]);
                            rounded = std::memcmp(&want, &got, sizeof(float)) == 0;
                        }
                        EXPECT_TRUE(rounded) << which << ": float32 distances";
                        EXPECT_TRUE(same_masks(f32)) << which << ": float32 distances, the mask";
                        if (run.on_device) {
                            EXPECT_EQ(f32.sampler.details["band_blocks_on_device"]["distance_type"], "float32") << which;
                        }
                    }
                }
                if (HasFailure()) return;
            }
    }
}

TEST(CudaSparseBand, BoundedSearchAndFloodEqualTheDenseBand) {
    const std::vector<test::BandSolid> cases = test::band_solids(1.25);
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
                    const SampledField dense =
                        make_sampler(options("cpu", "bvh", precision, w, SignMode::Auto))->bind(share(c.mesh))->sample(lattice);
                    for (int64_t piece : {int64_t(0), int64_t(5 * 512)}) {
                        SamplerOptions o = options("cuda", "bvh", precision, 0, SignMode::Auto);
                        o.kernel = "warp";
                        o.max_points_per_piece = piece;
                        const SparseBandField sparse = make_sampler(o)->bind(share(c.mesh))->sample_band_sparse(lattice, w);
                        const nlohmann::json& d = sparse.sampler.details["band_blocks_on_device"];
                        EXPECT_EQ(d["bounded_search"].get<bool>(), spacings >= 1.0) << what;
                        if (spacings >= 1.0) {
                            EXPECT_GT(d["points_flooded"].get<int64_t>(), 0) << what;
                        }
                        flooded += d["points_flooded"].get<int64_t>();
                        searched_blocks += d["blocks_signed_by_a_search"].get<int64_t>();
                        EXPECT_TRUE(same_field(dense, sparse.densify())) << what << " piece " << piece;
                    }
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
            const SampledField dense =
                make_sampler(options("cpu", "bvh", precision, w, SignMode::Auto))->bind(share(box))->sample(lattice);
            SamplerOptions o = options("cuda", "bvh", precision, 0, SignMode::Auto);
            o.kernel = "warp";
            const SparseBandField sparse = make_sampler(o)->bind(share(box))->sample_band_sparse(lattice, w);
            const nlohmann::json& d = sparse.sampler.details["band_blocks_on_device"];
            searched_blocks += d["blocks_signed_by_a_search"].get<int64_t>();
            EXPECT_TRUE(same_field(dense, sparse.densify())) << what;
        }
    EXPECT_GT(flooded, 0);
    EXPECT_GT(searched_blocks, 0) << "no block was all beyond the band: the search for its side went untested";
}

// Slivers of every kind (down to those searched by their edges alone), within a float ulp of
// the tetrahedron's sharp edges, and exact ties at their shared vertices and edges: the
// triangle sweep (W >= one spacing), the search with its brick skip (W below: each skipped
// brick's side from its centre's double-search triangle) and the dense band, against the CPU's
// dense band byte for byte and the exact winding number's sides.
TEST(CudaSparseBand, SliversAndTiesEqualTheCpuDenseBand) {
    int64_t flooded = 0;
    test::for_each_fan_case({0.9, 1.0, 3.0}, [&](const test::FanCase& c) {
        const SampledField cpu = make_sampler(options("cpu", "bvh", c.precision, c.width, SignMode::Auto))->bind(share(c.mesh))->sample(c.lattice);
        const SampledField winding =
            make_sampler(options("cpu", "bvh", c.precision, c.width, SignMode::Winding))->bind(share(c.mesh))->sample(c.lattice);
        EXPECT_EQ(test::sides_off_the_winding_number(cpu, winding), 0) << c.name << ": the CPU's signs off the winding number's";
        SamplerOptions dense_options = options("cuda", "bvh", c.precision, c.width, SignMode::Auto);
        dense_options.kernel = "warp";
        const SampledField gpu_dense = make_sampler(dense_options)->bind(share(c.mesh))->sample(c.lattice);
        EXPECT_TRUE(same_field(cpu, gpu_dense)) << c.name << ": the dense bands differ";
        SamplerOptions o = options("cuda", "bvh", c.precision, 0, SignMode::Auto);
        o.kernel = "warp";
        const SparseBandField sparse = make_sampler(o)->bind(share(c.mesh))->sample_band_sparse(c.lattice, c.width);
        const nlohmann::json& d = sparse.sampler.details["band_blocks_on_device"];
        EXPECT_EQ(d["nearest"], c.spacings >= 1.0 ? "triangle_sweep" : "search") << c.name;
        flooded += d["points_flooded"].get<int64_t>();
        EXPECT_TRUE(same_field(cpu, sparse.densify())) << c.name << ": the sparse band";
    });
    EXPECT_GT(flooded, 0);
}

}  // namespace
}  // namespace sdf
