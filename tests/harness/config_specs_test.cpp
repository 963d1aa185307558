// The config specs: lattices (CC/BCC resolution, the thesis's BCC notation, sample counts),
// lattice placement around a mesh, sampler options, mesh specs, the data search path and
// the "mesh not found" message. Expected numbers are worked out by hand in the comments.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "harness/build_config.h"
#include "harness/config/lattice_spec.h"
#include "harness/config/mesh_spec.h"
#include "harness/config/sampler_spec.h"
#include "harness/sampling/sampler_table.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::Contains;
using test::error_of;

/// Parses one lattice object as the runner does (path "lattices[0]", then finish()).
LatticeSpec lattice(const json& j) {
    JsonReader r(j, "cfg.json", "lattices[0]");
    LatticeSpec spec = parse_lattice_spec(r);
    r.finish();
    return spec;
}

SamplerOptions sampler(const json& j) {
    JsonReader r(j, "cfg.json", "sampler");
    return parse_sampler_options(r);
}

MeshSpec mesh_spec(const json& mesh) {
    const json root = {{"mesh", mesh}};
    JsonReader r(root, "cfg.json");
    return parse_mesh_spec(r, "mesh");
}

Bounds3 bounds(Vec3d lo, Vec3d hi) {
    Bounds3 b;
    b.extend(lo);
    b.extend(hi);
    return b;
}

// ---- parse_lattice_spec ----------------------------------------------------------------

TEST(LatticeSpec, CcResolution) {
    const LatticeSpec s = lattice({{"type", "cc"}, {"resolution", {80, 70, 60}}});
    EXPECT_EQ(s.type, LatticeType::CC);
    EXPECT_EQ(s.resolution, (Int3{80, 70, 60}));
    EXPECT_EQ(s.samples, 0);
    EXPECT_LT(s.margin, 0);  // "use the config's domain margin"
}

TEST(LatticeSpec, TypeDefaultsToCc) {
    EXPECT_EQ(lattice({{"resolution", {4, 4, 4}}}).type, LatticeType::CC);
}

TEST(LatticeSpec, BccThesisNotationGivesPrimaryResolution) {
    // [Rx, Ry, 2Rz] -> (Rx, Ry, Rz)
    EXPECT_EQ(lattice({{"type", "bcc"}, {"resolution", {64, 64, 128}}}).resolution, (Int3{64, 64, 64}));
    EXPECT_EQ(lattice({{"type", "bcc"}, {"resolution", {6, 6, 12}}}).resolution, (Int3{6, 6, 6}));
    EXPECT_EQ(lattice({{"type", "bcc"}, {"resolution", {10, 12, 20}}}).resolution, (Int3{10, 12, 10}));
    EXPECT_EQ(lattice({{"type", "bcc"}, {"resolution", {3, 5, 4}}}).resolution, (Int3{3, 5, 2}));
    EXPECT_EQ(bcc_primary_from_notation({26, 26, 52}), (Int3{26, 26, 26}));
}

TEST(LatticeSpec, BccOddSecondEntryRejectedNamingKeyAndValue) {
    const std::string msg = error_of([] { lattice({{"type", "bcc"}, {"resolution", {6, 6, 13}}}); });
    EXPECT_TRUE(Contains(msg, "cfg.json"));
    EXPECT_TRUE(Contains(msg, "'lattices[0].resolution'"));
    EXPECT_TRUE(Contains(msg, "2Rz"));
    EXPECT_TRUE(Contains(msg, "even"));
    EXPECT_TRUE(Contains(msg, "13"));
    EXPECT_ANY_THROW(bcc_primary_from_notation({6, 6, 13}));
}

TEST(LatticeSpec, BccNeedsAtLeastTwoPrimaryLayers) {
    // [4, 4, 2] would be a primary grid of one layer and no secondary points.
    EXPECT_TRUE(Contains(error_of([] { lattice({{"type", "bcc"}, {"resolution", {4, 4, 2}}}); }), "'lattices[0].resolution'"));
}

TEST(LatticeSpec, BadResolutionsRejected) {
    for (const json& res : {json{4, 4}, json{4, 4, 4, 4}, json{1, 4, 4}, json{4, 0, 4}, json{4, 4, -3}, json("80"), json(80)}) {
        const std::string msg = error_of([&] { lattice({{"type", "cc"}, {"resolution", res}}); });
        EXPECT_TRUE(Contains(msg, "'lattices[0].resolution'")) << res.dump();
        EXPECT_TRUE(Contains(msg, "3 integers")) << res.dump();
    }
}

TEST(LatticeSpec, FractionalResolutionEntryRejected) {
    const std::string msg = error_of([] { lattice({{"type", "cc"}, {"resolution", {80, 80.5, 80}}}); });
    EXPECT_TRUE(Contains(msg, "'lattices[0].resolution'"));
    EXPECT_TRUE(Contains(msg, "80.5"));
}

TEST(LatticeSpec, BadResolutionQuotesTheValueSeen) {
    const std::string msg = error_of([] { lattice({{"type", "cc"}, {"resolution", {4, 4}}}); });
    EXPECT_TRUE(Contains(msg, "expected an array of 3 integers >= 2, got [4,4]"));
}

TEST(LatticeSpec, UnknownTypeSuggestsNearest) {
    const std::string msg = error_of([] { lattice({{"type", "bbc"}, {"resolution", {4, 4, 8}}}); });
    EXPECT_TRUE(Contains(msg, "'lattices[0].type'"));
    EXPECT_TRUE(Contains(msg, "did you mean \"bcc\""));
}

TEST(LatticeSpec, ExactlyOneOfResolutionAndSamples) {
    const std::string both = error_of([] { lattice({{"type", "bcc"}, {"resolution", {4, 4, 8}}, {"samples", 1000}}); });
    EXPECT_TRUE(Contains(both, "cfg.json: key 'lattices[0]."));
    EXPECT_TRUE(Contains(both, "exactly one of \"resolution\" and \"samples\""));
    const std::string neither = error_of([] { lattice({{"type", "cc"}}); });
    EXPECT_TRUE(Contains(neither, "'lattices[0].resolution'"));
    EXPECT_TRUE(Contains(neither, "exactly one of"));
}

TEST(LatticeSpec, SamplesGiveCubicResolutionNearestInCount) {
    const LatticeSpec cc = lattice({{"type", "cc"}, {"samples", 512000}});
    EXPECT_EQ(cc.samples, 512000);
    EXPECT_EQ(cc.resolution, (Int3{0, 0, 0}));
    const Bounds3 b = bounds({-1, -1, -1}, {1, 1, 1});
    EXPECT_EQ(build_lattice(cc, b, 0.1).resolution, (Int3{80, 80, 80}));  // 80^3 = 512,000
    // BCC: 64^3 + 63^3 = 262,144 + 250,047 = 512,191 (63: 488,375; 65: 536,769).
    const LatticeSpec bcc = lattice({{"type", "bcc"}, {"samples", 512000}});
    const Lattice l = build_lattice(bcc, b, 0.1);
    EXPECT_EQ(l.type, LatticeType::BCC);
    EXPECT_EQ(l.resolution, (Int3{64, 64, 64}));
    EXPECT_EQ(l.num_points(), 512191);
    // 68^3 + 67^3 = 314,432 + 300,763 = 615,195 (67: 588,259; 69: 642,941); the midpoint
    // between 67 and 68 is 601,727.
    EXPECT_EQ(cubic_resolution_for_samples(LatticeType::BCC, 615000), 68);
    EXPECT_EQ(cubic_resolution_for_samples(LatticeType::BCC, 601000), 67);
    EXPECT_EQ(cubic_resolution_for_samples(LatticeType::BCC, 602500), 68);
    EXPECT_EQ(cubic_resolution_for_samples(LatticeType::BCC, 640000), 69);
    // 85^3 = 614,125, 86^3 = 636,056.
    EXPECT_EQ(cubic_resolution_for_samples(LatticeType::CC, 615000), 85);
    EXPECT_EQ(cubic_resolution_for_samples(LatticeType::CC, 8), 2);
    EXPECT_EQ(cubic_resolution_for_samples(LatticeType::BCC, 9), 2);  // 2^3 + 1^3
    EXPECT_EQ(cubic_lattice_points(LatticeType::BCC, 64), 512191);
    EXPECT_EQ(cubic_lattice_points(LatticeType::CC, 80), 512000);
}

TEST(LatticeSpec, BadSampleCountsRejected) {
    EXPECT_TRUE(Contains(error_of([] { lattice({{"type", "cc"}, {"samples", 7}}); }), "'lattices[0].samples'"));
    EXPECT_TRUE(Contains(error_of([] { lattice({{"type", "cc"}, {"samples", -100}}); }), "'lattices[0].samples'"));
    const std::string msg = error_of([] { lattice({{"type", "cc"}, {"samples", "many"}}); });
    EXPECT_TRUE(Contains(msg, "'lattices[0].samples'"));
    EXPECT_TRUE(Contains(msg, "\"many\""));
}

TEST(LatticeSpec, MarginOverrideAndUnknownKeys) {
    EXPECT_DOUBLE_EQ(lattice({{"resolution", {4, 4, 4}}, {"margin", 0.25}}).margin, 0.25);
    const std::string msg = error_of([] { lattice({{"resolution", {4, 4, 4}}, {"margn", 0.25}}); });
    EXPECT_TRUE(Contains(msg, "unknown key 'lattices[0].margn'"));
    EXPECT_TRUE(Contains(msg, "did you mean 'margin'?"));
}

// A negative per-lattice margin is rejected (as "domain": {"margin": -0.3} is), quoting it.
TEST(LatticeSpec, NegativeMarginRejected) {
    const std::string msg = error_of([] { lattice({{"resolution", {4, 4, 4}}, {"margin", -0.3}}); });
    EXPECT_TRUE(Contains(msg, "'lattices[0].margin'"));
    EXPECT_TRUE(Contains(msg, "-0.3"));
    EXPECT_DOUBLE_EQ(lattice({{"resolution", {4, 4, 4}}, {"margin", 0.0}}).margin, 0.0);
}

TEST(LatticeSpec, LabelsAreUniqueAndGivenNamesChecked) {
    const json cfg = json::object();
    JsonReader r(cfg, "cfg.json");
    const LatticeSpec cc = lattice({{"type", "cc"}, {"resolution", {4, 4, 4}}});
    const LatticeSpec bcc = lattice({{"type", "bcc"}, {"samples", 100}});
    EXPECT_EQ(lattice_spec_labels({cc, bcc, cc}, r), (std::vector<std::string>{"cc-4x4x4", "bcc-4x4x8", "cc-4x4x4-2"}));
    const LatticeSpec named = lattice({{"type", "cc"}, {"resolution", {4, 4, 4}}, {"name", "coarse"}});
    EXPECT_EQ(lattice_spec_labels({named, cc}, r), (std::vector<std::string>{"coarse", "cc-4x4x4"}));
    const std::string msg = error_of([&] { lattice_spec_labels({named, cc, named}, r); });
    EXPECT_TRUE(Contains(msg, "'lattices[2].name'"));
    EXPECT_TRUE(Contains(msg, "\"coarse\""));
    EXPECT_TRUE(Contains(error_of([] { lattice({{"resolution", {4, 4, 4}}, {"name", ".."}}); }), "'lattices[0].name'"));
}

// ---- build_lattice / fit_lattice ----------------------------------------------------------

// Bounds [-1,3] x [-2,1] x [-0.5,0.5]: extent (4, 3, 1), largest 4; margin 0.1 pads 0.4 on
// every side. Resolution (11, 9, 5): spacings needed 4.8/10 = 0.48, 3.8/8 = 0.475,
// 1.8/4 = 0.45, so h = 0.48 (x decides) and the lattice is centred on (1, -0.5, 0).
TEST(FitLattice, ContainsBoundsPlusMarginIsotropicAndCentred) {
    const Bounds3 b = bounds({-1, -2, -0.5}, {3, 1, 0.5});
    for (LatticeType type : {LatticeType::CC, LatticeType::BCC}) {
        LatticeSpec spec;
        spec.type = type;
        spec.resolution = {11, 9, 5};
        const Lattice l = build_lattice(spec, b, 0.1);
        EXPECT_EQ(l.type, type);
        EXPECT_EQ(l.resolution, (Int3{11, 9, 5}));
        EXPECT_NEAR(l.spacing, 0.48, 1e-15);
        const double pad = 0.4;
        for (int a = 0; a < 3; ++a) {
            EXPECT_LE(l.domain_min()[a], b.min[a] - pad + 1e-12) << "axis " << a;
            EXPECT_GE(l.domain_max()[a], b.max[a] + pad - 1e-12) << "axis " << a;
            EXPECT_NEAR(0.5 * (l.domain_min()[a] + l.domain_max()[a]), b.center()[a], 1e-12) << "axis " << a;
        }
        // x decides the spacing, so the domain fits exactly along x.
        EXPECT_NEAR(l.domain_min().x, -1.4, 1e-12);
        EXPECT_NEAR(l.domain_max().x, 3.4, 1e-12);
        EXPECT_NEAR(l.domain_max().z - l.domain_min().z, 4 * 0.48, 1e-12);
        EXPECT_EQ(l.num_points(), type == LatticeType::CC ? 11 * 9 * 5 : 11 * 9 * 5 + 10 * 8 * 4);
    }
}

TEST(FitLattice, PerLatticeMarginOverridesDefault) {
    const Bounds3 b = bounds({0, 0, 0}, {2, 2, 2});
    LatticeSpec spec;
    spec.resolution = {5, 5, 5};
    spec.margin = 0.25;  // pad 0.5: domain [-0.5, 2.5], h = 3/4
    const Lattice l = build_lattice(spec, b, 0.1);
    EXPECT_NEAR(l.spacing, 0.75, 1e-15);
    EXPECT_NEAR(l.origin.x, -0.5, 1e-15);
    spec.margin = -1;  // unset: the default 0 -> domain [0, 2], h = 0.5
    const Lattice d = build_lattice(spec, b, 0.0);
    EXPECT_NEAR(d.spacing, 0.5, 1e-15);
    EXPECT_NEAR(d.origin.y, 0.0, 1e-15);
}

TEST(FitLattice, FlatMeshStillGetsAnIsotropicCube) {
    // A square in the z = 1 plane: z has no extent but the margin pads it too.
    const Bounds3 b = bounds({0, 0, 1}, {1, 1, 1});
    const Lattice l = fit_lattice(LatticeType::CC, {6, 6, 6}, b, 0.1);
    EXPECT_NEAR(l.spacing, 1.2 / 5, 1e-15);
    EXPECT_NEAR(l.origin.z, 1 - 0.6, 1e-12);
}

TEST(FitLattice, RejectsTinyResolutionAndEmptyBounds) {
    const Bounds3 b = bounds({0, 0, 0}, {1, 1, 1});
    EXPECT_TRUE(Contains(error_of([&] { fit_lattice(LatticeType::CC, {8, 1, 8}, b, 0.1); }), "at least 2"));
    EXPECT_TRUE(Contains(error_of([&] { fit_lattice(LatticeType::CC, {8, 8, 8}, Bounds3{}, 0.1); }), "empty mesh"));
}

// ---- parse_sampler_options ---------------------------------------------------------------

// Issue 23: the fast defaults, the same for configs, tools and Python: the exact BVH on the
// backend "auto", resolved when the options are read.
TEST(SamplerSpec, Defaults) {
    const SamplerOptions o = sampler(json::object());
    EXPECT_EQ(o.backend, cuda_backend_available() ? "cuda" : "cpu");
    EXPECT_EQ(o.method, "bvh");
    EXPECT_EQ(o.band_width, 0.0);
    EXPECT_EQ(o.kernel, "");
    EXPECT_EQ(o.threads, 0);
    EXPECT_EQ(o.precision, Precision::Float);
    EXPECT_EQ(o.bcc_strategy, BccStrategy::TwoGrids);
    EXPECT_TRUE(o.progress);
    EXPECT_EQ(o.device, 0);
    EXPECT_EQ(o.max_points_per_piece, 0);
    EXPECT_EQ(o.max_triangles_per_chunk, 0);
    EXPECT_EQ(o.points_per_thread, 0);
    EXPECT_EQ(o.bvh_build, BvhBuildSite::Auto);
    EXPECT_EQ(o.min_points_per_device, kDefaultMinPointsPerDevice);
}

TEST(SamplerSpec, EveryKeyReadAndWrittenBack) {
    const json j = {{"backend", "cuda"},        {"method", "brute_force"},  {"kernel", "tuned"},
                    {"threads", 3},             {"precision", "double"},    {"bcc_strategy", "double_resolution"},
                    {"progress", false},        {"device", 1},              {"max_points_per_piece", 5000000000LL},
                    {"max_triangles_per_chunk", 4096}, {"points_per_thread", 4}, {"band_width", 0.125},
                    {"bvh_build", "host"}, {"min_points_per_device", 1}};
    const SamplerOptions o = sampler(j);
    EXPECT_EQ(o.backend, "cuda");
    EXPECT_EQ(o.kernel, "tuned");
    EXPECT_EQ(o.threads, 3);
    EXPECT_EQ(o.precision, Precision::Double);
    EXPECT_EQ(o.bcc_strategy, BccStrategy::DoubleResolution);
    EXPECT_FALSE(o.progress);
    EXPECT_EQ(o.device, 1);
    EXPECT_EQ(o.max_points_per_piece, 5000000000LL);
    EXPECT_EQ(o.max_triangles_per_chunk, 4096);
    EXPECT_EQ(o.points_per_thread, 4);
    const json back = sampler_options_to_json(o);
    EXPECT_EQ(back.at("backend"), "cuda");
    EXPECT_EQ(back.at("precision"), "double");
    EXPECT_EQ(back.at("bcc_strategy"), "double_resolution");
    EXPECT_EQ(back.at("threads"), 3);
    EXPECT_EQ(back.at("max_points_per_piece"), 5000000000LL);
    EXPECT_EQ(back.at("points_per_thread"), 4);
    EXPECT_EQ(back.at("sign"), "auto");  // the default
    EXPECT_EQ(back.at("band_width"), 0.125);
    EXPECT_EQ(back.at("progress"), false);
    EXPECT_EQ(back.at("bvh_build"), "host");
    EXPECT_EQ(back.at("min_points_per_device"), 1);
    // The codec reads back what it writes: every field of the table, nothing lost.
    JsonReader again(back, "wire", "sampler");
    EXPECT_EQ(sampler_options_to_json(parse_sampler_options(again)), back);
    EXPECT_EQ(back.size(), kSamplerOptionFields);
}

TEST(SamplerSpec, SignModeIsReadAndWritten) {
    EXPECT_EQ(sampler(json::object()).sign, SignMode::Auto);
    EXPECT_EQ(sampler({{"sign", "pseudonormal"}}).sign, SignMode::Pseudonormal);
    const SamplerOptions w = sampler({{"sign", "winding"}});
    EXPECT_EQ(w.sign, SignMode::Winding);
    EXPECT_EQ(sampler_options_to_json(w).at("sign"), "winding");
}

TEST(SamplerSpec, BadValuesNameTheKey) {
    struct Case {
        json config;
        std::string key, expect;
    };
    const std::vector<Case> cases = {
        {{{"threads", -1}}, "'sampler.threads'", "0 or a positive number, got -1"},
        {{{"device", -2}}, "'sampler.device'", "a CUDA device ordinal"},
        {{{"band_width", -0.5}}, "'sampler.band_width'", "a finite number >= 0, got -0.5"},
        {{{"band_width", "wide"}}, "'sampler.band_width'", "a band width"},
        {{{"method", "octree"}}, "'sampler.method'", "\"brute_force\" or \"bvh\""},
        {{{"backend", "auto"}, {"kernel", "brick"}}, "'sampler.kernel'", "\"auto\" takes no kernel"},
        {{{"backend", "cpu"}, {"kernel", "eberly"}}, "'sampler.kernel'", "unknown cpu bvh kernel \"eberly\""},
        {{{"threads", "2"}}, "'sampler.threads'", "\"2\""},
        {{{"threads", 1.5}}, "'sampler.threads'", "a thread count"},
        {{{"precision", "doubel"}}, "'sampler.precision'", "did you mean \"double\""},
        {{{"bcc_strategy", "two_grid"}}, "'sampler.bcc_strategy'", "did you mean \"two_grids\""},
        {{{"sign", "windng"}}, "'sampler.sign'", "did you mean \"winding\""},
        {{{"sign", "parity"}}, "'sampler.sign'", "\"auto\", \"pseudonormal\" or \"winding\""},
        {{{"sign", true}}, "'sampler.sign'", "one of \"auto\""},
        {{{"backend", "opencl"}}, "'sampler.backend'", "\"auto\", \"cpu\" or \"cuda\""},
        {{{"points_per_thread", 3}}, "'sampler.points_per_thread'", "0, 1, 2, 4 or 8, got 3"},
        {{{"progress", 1}}, "'sampler.progress'", "true or false"},
        {{{"thread", 2}}, "unknown key 'sampler.thread'", "did you mean 'threads'?"},
    };
    for (const Case& c : cases) {
        const std::string msg = error_of([&] { sampler(c.config); });
        EXPECT_TRUE(Contains(msg, "cfg.json")) << c.config.dump();
        EXPECT_TRUE(Contains(msg, c.key)) << c.config.dump();
        EXPECT_TRUE(Contains(msg, c.expect)) << c.config.dump();
    }
}

// ---- mesh specs -------------------------------------------------------------------------

TEST(MeshSpec, FileNameAsStringOrObject) {
    const MeshSpec a = mesh_spec("dragon.obj");
    EXPECT_EQ(a.file, "dragon.obj");
    EXPECT_TRUE(a.shape.empty());
    EXPECT_EQ(a.label(), "dragon.obj");
    const MeshSpec b = mesh_spec({{"file", "meshes/x.obj"}});
    EXPECT_EQ(b.file, "meshes/x.obj");
    EXPECT_TRUE(b.shape.empty());
}

TEST(MeshSpec, ProceduralShapeWithParameters) {
    const MeshSpec s = mesh_spec({{"shape", "sphere"}, {"subdivisions", 2}, {"radius", 0.5}});
    EXPECT_EQ(s.shape, "sphere");
    EXPECT_TRUE(s.file.empty());
    EXPECT_EQ(s.label(), "sphere");
    EXPECT_EQ(s.parameters, (json{{"subdivisions", 2}, {"radius", 0.5}}));
}

TEST(MeshSpec, ShapeColonNameStringAndArgument) {
    const MeshSpec s = mesh_spec("shape:torus");
    EXPECT_EQ(s.shape, "torus");
    EXPECT_TRUE(s.file.empty());
    EXPECT_TRUE(s.parameters.is_object());
    EXPECT_TRUE(s.parameters.empty());
    const MeshSpec a = mesh_spec_from_argument("shape:box");
    EXPECT_EQ(a.shape, "box");
    const MeshSpec f = mesh_spec_from_argument("bunny.obj");
    EXPECT_EQ(f.file, "bunny.obj");
    EXPECT_TRUE(f.shape.empty());
}

TEST(MeshSpec, BadSpecsNameTheKey) {
    const std::string num = error_of([] { mesh_spec(42); });
    EXPECT_TRUE(Contains(num, "cfg.json: key 'mesh'"));
    EXPECT_TRUE(Contains(num, "expected a file name or an object"));
    const std::string shape = error_of([] { mesh_spec({{"shape", "bxo"}}); });
    EXPECT_TRUE(Contains(shape, "'mesh.shape'"));
    EXPECT_TRUE(Contains(shape, "did you mean \"box\""));
    const std::string extra = error_of([] { mesh_spec({{"file", "x.obj"}, {"flie", "y"}}); });
    EXPECT_TRUE(Contains(extra, "unknown key 'mesh.flie'"));
    EXPECT_TRUE(Contains(extra, "did you mean 'file'?"));
    EXPECT_TRUE(Contains(error_of([] { mesh_spec({{"file", 3}}); }), "'mesh.file'"));
    const std::string missing = error_of([] {
        const json root = json::object();
        JsonReader r(root, "cfg.json");
        parse_mesh_spec(r, "mesh");
    });
    EXPECT_TRUE(Contains(missing, "cfg.json: key 'mesh': missing"));
}

// {"file": ..., "shape": ...}: exclusive, said so.
TEST(MeshSpec, FileAndShapeTogetherAreReportedAsExclusive) {
    const std::string msg = error_of([] { mesh_spec({{"file", "x.obj"}, {"shape", "box"}}); });
    EXPECT_TRUE(Contains(msg, "cfg.json: key 'mesh'"));
    EXPECT_TRUE(Contains(msg, "give either 'file' or 'shape', not both"));
    EXPECT_FALSE(Contains(msg, "unknown key"));
    EXPECT_TRUE(Contains(error_of([] { mesh_spec(json::object()); }), "expected {\"file\": NAME}"));
    EXPECT_TRUE(Contains(error_of([] { mesh_spec({{"file", ""}}); }), "'mesh.file'"));
    EXPECT_TRUE(Contains(error_of([] { mesh_spec(""); }), "'mesh'"));
}

// "shape:" with no name is an error about the shape, not a file named "".
TEST(LoadMesh, EmptyShapeNameIsReportedAsSuch) {
    const std::string msg = error_of([] { load_mesh(mesh_spec_from_argument("shape:"), {"/nonexistent"}); });
    EXPECT_TRUE(Contains(msg, "needs a shape name"));
    EXPECT_FALSE(Contains(msg, "not found"));
    EXPECT_TRUE(Contains(error_of([] { mesh_spec("shape:"); }), "cfg.json: key 'mesh'"));
}

TEST(LoadMesh, ProceduralBox) {
    const TriangleMesh box = load_mesh(mesh_spec_from_argument("shape:box"), {});
    EXPECT_EQ(box.vertices.size(), 8u);
    EXPECT_EQ(box.triangles.size(), 12u);
    const TriangleMesh big = load_mesh(mesh_spec({{"shape", "box"}, {"half_extent", {2, 3, 4}}}), {});
    const Bounds3 b = triangle_bounds(big.vertices, big.triangles);
    EXPECT_EQ(b.max, (Vec3d{2, 3, 4}));
    EXPECT_EQ(b.min, (Vec3d{-2, -3, -4}));
}

TEST(LoadMesh, UnknownShapeSuggestsNearest) {
    const std::string msg = error_of([] { load_mesh(mesh_spec_from_argument("shape:spere"), {}); });
    EXPECT_TRUE(Contains(msg, "'spere'"));
    EXPECT_TRUE(Contains(msg, "did you mean 'sphere'?"));
    const std::string far = error_of([] { load_mesh(mesh_spec_from_argument("shape:teapot_xyz"), {}); });
    EXPECT_TRUE(Contains(far, "'teapot_xyz'"));
}

TEST(LoadMesh, ShapeParameterErrorsNameTheParameter) {
    const std::string typo = error_of([] { load_mesh(mesh_spec({{"shape", "box"}, {"half_extnt", {1, 1, 1}}}), {}); });
    EXPECT_TRUE(Contains(typo, "'mesh.half_extnt'"));
    EXPECT_TRUE(Contains(typo, "did you mean 'half_extent'?"));
    const std::string range = error_of([] { load_mesh(mesh_spec({{"shape", "sphere"}, {"subdivisions", 9}}), {}); });
    EXPECT_TRUE(Contains(range, "'mesh.subdivisions'"));
    EXPECT_TRUE(Contains(range, "from 0 to 8, got 9"));
    const std::string size = error_of([] { load_mesh(mesh_spec({{"shape", "box"}, {"center", {1, 2}}}), {}); });
    EXPECT_TRUE(Contains(size, "'mesh.center'"));
    EXPECT_TRUE(Contains(size, "3 numbers"));
}

// Every parameter is range-checked; the message names the key and the value seen.
TEST(LoadMesh, OutOfRangeShapeParametersRejected) {
    struct Case {
        json spec;
        std::string key, value;
    };
    const std::vector<Case> bad = {
        {{{"shape", "sphere"}, {"radius", -1.0}}, "'mesh.radius'", "-1"},
        {{{"shape", "sphere"}, {"radius", 0}}, "'mesh.radius'", "got 0"},
        {{{"shape", "box"}, {"half_extent", {1, -1, 1}}}, "'mesh.half_extent'", "[1,-1,1]"},
        {{{"shape", "box"}, {"half_extent", {0, 0, 0}}}, "'mesh.half_extent'", "[0,0,0]"},
        {{{"shape", "torus"}, {"major_segments", 1}}, "'mesh.major_segments'", "got 1"},
        {{{"shape", "torus"}, {"minor_segments", 2}}, "'mesh.minor_segments'", "got 2"},
        {{{"shape", "torus"}, {"minor_radius", 0.0}}, "'mesh.minor_radius'", "got 0"},
        {{{"shape", "torus"}, {"minor_radius", 1.5}}, "'mesh.minor_radius'", "1.5"},
        {{{"shape", "torus"}, {"minor_radius", 1.0}}, "'mesh.minor_radius'", "intersect"},
        {{{"shape", "torus"}, {"major_radius", -2.0}}, "'mesh.major_radius'", "-2"},
        {{{"shape", "pawn"}, {"segments", 2}}, "'mesh.segments'", "got 2"},
        {{{"shape", "soccer_ball"}, {"seam_depth", -0.01}}, "'mesh.seam_depth'", "-0.01"},
        {{{"shape", "soccer_ball"}, {"seam_depth", 0.5}}, "'mesh.seam_depth'", "0.5"},
        {{{"shape", "soccer_ball"}, {"seam_width", 0.0}}, "'mesh.seam_width'", "got 0"},
        {{{"shape", "soccer_ball"}, {"detail", -1}}, "'mesh.detail'", "got -1"},
    };
    for (const Case& c : bad) {
        const std::string msg = error_of([&] { load_mesh(mesh_spec(c.spec), {}); });
        EXPECT_TRUE(Contains(msg, "cfg.json")) << c.spec.dump();
        EXPECT_TRUE(Contains(msg, c.key)) << c.spec.dump();
        EXPECT_TRUE(Contains(msg, c.value)) << c.spec.dump();
    }
    // The edges of the valid ranges build.
    EXPECT_EQ(load_mesh(mesh_spec({{"shape", "torus"}, {"major_segments", 3}, {"minor_segments", 3}}), {}).triangles.size(), 18u);
    EXPECT_GT(load_mesh(mesh_spec({{"shape", "soccer_ball"}, {"detail", 0}, {"seam_depth", 0.0}}), {}).triangles.size(), 0u);
}

// Parameters are checked when the spec is parsed (a dry run sees them), and the errors of the
// built shape name the config file the spec came from.
TEST(MeshSpec, ShapeParametersCheckedAtParseTimeNamingTheFile) {
    EXPECT_TRUE(Contains(error_of([] { mesh_spec({{"shape", "sphere"}, {"radius", -1.0}}); }), "cfg.json: key 'mesh.radius'"));
    const std::string unknown = error_of([] { mesh_spec("shape:bxo"); });
    EXPECT_TRUE(Contains(unknown, "cfg.json: key 'mesh'"));
    EXPECT_TRUE(Contains(unknown, "did you mean 'box'?"));
    MeshSpec spec = mesh_spec({{"shape", "box"}});
    spec.parameters["half_extnt"] = {1, 1, 1};  // edited after parsing: caught when building
    const std::string built = error_of([&] { load_mesh(spec, {}); });
    EXPECT_TRUE(Contains(built, "cfg.json: unknown key 'mesh.half_extnt'"));
}

// ---- files: search path, locating, loading ------------------------------------------------

/// A scratch directory, and $SDF_DATA_PATH restored after each test.
class MeshFiles : public test::ScratchDirTest {
protected:
    MeshFiles() : ScratchDirTest("sdf_config_specs_test") {}
    void SetUp() override {
        ScratchDirTest::SetUp();
        if (const char* v = std::getenv("SDF_DATA_PATH")) saved_ = std::string(v);
    }
    void TearDown() override {
        if (saved_) ::setenv("SDF_DATA_PATH", saved_->c_str(), 1);
        else ::unsetenv("SDF_DATA_PATH");
        ScratchDirTest::TearDown();
    }
    static std::vector<std::string> defaults() {
        std::vector<std::string> out;
        std::stringstream ss(SDF_DATA_DIR_DEFAULT);
        for (std::string item; std::getline(ss, item, '|');)
            if (!item.empty()) out.push_back(item);
        return out;
    }
    std::optional<std::string> saved_;
};

const char* kTetrahedron = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST_F(MeshFiles, SearchPathOrderConfigThenEnvThenDefaults) {
    ::setenv("SDF_DATA_PATH", "/env/a::/env/b", 1);
    const std::vector<std::string> p = data_search_path({"meshes", "/abs/dir"}, "/cfg/dir");
    std::vector<std::string> want = {(fs::path("/cfg/dir") / "meshes").string(), "/abs/dir", "/env/a", "/env/b"};
    for (const auto& d : defaults()) want.push_back(d);
    EXPECT_EQ(p, want);
    EXPECT_GE(defaults().size(), 1u);
}

TEST_F(MeshFiles, SearchPathWithoutEnvOrConfigIsTheDefaults) {
    ::unsetenv("SDF_DATA_PATH");
    EXPECT_EQ(data_search_path(), defaults());
    // Without a config directory, relative entries stay relative (to the working directory).
    EXPECT_EQ(data_search_path({"rel"}, "").front(), "rel");
}

TEST_F(MeshFiles, LocateFindsFirstMatchOnPath) {
    const std::string first = write("a/m.obj", kTetrahedron);
    write("b/m.obj", kTetrahedron);
    const std::vector<std::string> path = {(dir_ / "missing").string(), (dir_ / "a").string(), (dir_ / "b").string()};
    EXPECT_EQ(fs::path(locate_mesh_file("m.obj", path)), fs::weakly_canonical(first));
    // Absolute names are used as they are.
    EXPECT_EQ(locate_mesh_file(first, {}), first);
}

// Relative names: the base directory (the config's own, or the working directory for
// sdf-query) first, then the search path; the result is absolute; "not found" lists all.
TEST_F(MeshFiles, BaseDirectoryFirstThenSearchPathAbsoluteResult) {
    write("cfg/m.obj", kTetrahedron);
    write("path/m.obj", kTetrahedron);
    write("path/only.obj", kTetrahedron);
    const std::vector<std::string> path = {(dir_ / "path").string()};
    EXPECT_EQ(fs::path(locate_mesh_file("m.obj", path, (dir_ / "cfg").string())), fs::weakly_canonical(dir_ / "cfg/m.obj"));
    EXPECT_EQ(fs::path(locate_mesh_file("only.obj", path, (dir_ / "cfg").string())),
              fs::weakly_canonical(dir_ / "path/only.obj"));
    EXPECT_EQ(fs::path(locate_mesh_file("m.obj", path)), fs::weakly_canonical(dir_ / "path/m.obj"));
    // A relative base directory still gives an absolute path.
    const fs::path saved = fs::current_path();
    fs::current_path(dir_);
    const std::string found = locate_mesh_file("m.obj", {}, "cfg");
    fs::current_path(saved);
    EXPECT_TRUE(fs::path(found).is_absolute()) << found;
    EXPECT_EQ(fs::path(found), fs::weakly_canonical(dir_ / "cfg/m.obj"));
    const std::string msg = error_of([&] { locate_mesh_file("none.obj", path, (dir_ / "cfg").string()); });
    EXPECT_TRUE(Contains(msg, (dir_ / "cfg/none.obj").string()));
    EXPECT_TRUE(Contains(msg, (dir_ / "path/none.obj").string()));
    // resolve_mesh_file records the path and names the config key on failure.
    MeshSpec spec = mesh_spec("m.obj");
    resolve_mesh_file(spec, path, (dir_ / "cfg").string());
    EXPECT_EQ(fs::path(spec.resolved_file), fs::weakly_canonical(dir_ / "cfg/m.obj"));
    MeshSpec missing = mesh_spec("none.obj");
    EXPECT_TRUE(Contains(error_of([&] { resolve_mesh_file(missing, path, ""); }), "cfg.json: key 'mesh'"));
}

TEST_F(MeshFiles, ConfigRelativeDataPathIsFound) {
    write("cfgdir/meshes/t.obj", kTetrahedron);
    ::unsetenv("SDF_DATA_PATH");
    const auto path = data_search_path({"meshes"}, (dir_ / "cfgdir").string());
    const TriangleMesh m = load_mesh(mesh_spec({{"file", "t.obj"}}), path);
    EXPECT_EQ(m.triangles.size(), 4u);
}

TEST_F(MeshFiles, EnvDataPathIsFound) {
    write("envdir/t.obj", kTetrahedron);
    ::setenv("SDF_DATA_PATH", ("/nonexistent/x:" + (dir_ / "envdir").string()).c_str(), 1);
    EXPECT_EQ(load_mesh(mesh_spec("t.obj"), data_search_path()).triangles.size(), 4u);
}

TEST_F(MeshFiles, NotFoundListsDirectoriesAndFetchScript) {
    const std::vector<std::string> path = {(dir_ / "one").string(), "/somewhere/two"};
    const std::string msg = error_of([&] { locate_mesh_file("dragon_missing.obj", path); });
    EXPECT_TRUE(Contains(msg, "dragon_missing.obj"));
    EXPECT_TRUE(Contains(msg, (dir_ / "one").string()));
    EXPECT_TRUE(Contains(msg, "/somewhere/two"));
    EXPECT_TRUE(Contains(msg, "scripts/fetch-meshes"));
    EXPECT_TRUE(Contains(msg, "SDF_DATA_PATH"));
    // Through load_mesh as well.
    EXPECT_TRUE(Contains(error_of([&] { load_mesh(mesh_spec("dragon_missing.obj"), path); }), "scripts/fetch-meshes"));
}

// scripts/run-main falls back to the procedural study on exactly this error (run-experiment
// exits 4 for it), so it must keep its own type through resolve_mesh_file, with the key named.
TEST_F(MeshFiles, NotFoundHasItsOwnTypeNamingTheKey) {
    const std::vector<std::string> path = {(dir_ / "one").string()};
    EXPECT_THROW(locate_mesh_file("dragon_missing.obj", path), MeshFileNotFound);
    MeshSpec spec = mesh_spec("dragon_missing.obj");
    spec.config_file = "study.json";
    try {
        resolve_mesh_file(spec, path, "");
        ADD_FAILURE() << "no exception";
    } catch (const MeshFileNotFound& e) {
        EXPECT_TRUE(Contains(e.what(), "study.json: key 'mesh'"));
        EXPECT_TRUE(Contains(e.what(), "dragon_missing.obj"));
    }
    // A file that exists but is not a mesh is a different error (exit 1, not the fallback).
    write("one/bad.obj", "v 0 0 0\n");
    MeshSpec found = mesh_spec("bad.obj");
    EXPECT_NO_THROW(resolve_mesh_file(found, path, ""));
}

TEST_F(MeshFiles, AbsoluteMissingOrDirectoryNamesTheFile) {
    const std::string missing = (dir_ / "nope.obj").string();
    EXPECT_TRUE(Contains(error_of([&] { locate_mesh_file(missing, {}); }), missing));
    fs::create_directories(dir_ / "adir.obj");
    EXPECT_TRUE(Contains(error_of([&] { locate_mesh_file((dir_ / "adir.obj").string(), {}); }), "adir.obj"));
}

TEST_F(MeshFiles, NonTriangleAndNanMeshesRejectedNamingTheFile) {
    const std::string lines = write("lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n");
    const std::string msg = error_of([&] { load_mesh(mesh_spec(lines), {}); });
    EXPECT_TRUE(Contains(msg, lines));
    EXPECT_TRUE(Contains(msg, "no triangles"));
    const std::string nan = write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
    const std::string nmsg = error_of([&] { load_mesh(mesh_spec(nan), {}); });
    EXPECT_TRUE(Contains(nmsg, nan + ":3"));
    EXPECT_TRUE(Contains(nmsg, "nan"));
    const std::string empty = write("empty.obj", "");
    EXPECT_TRUE(Contains(error_of([&] { load_mesh(mesh_spec(empty), {}); }), empty));
}

// The real meshes: ctest sets SDF_DATA_PATH to /work/shared/meshes.
TEST_F(MeshFiles, RealMeshesAreOnTheCtestSearchPath) {
    const std::vector<std::string> path = data_search_path();
    try {
        const std::string found = locate_mesh_file("bunny.obj", path);
        EXPECT_TRUE(fs::is_regular_file(found));
        EXPECT_EQ(fs::path(found).filename(), "bunny.obj");
    } catch (const std::exception& e) {
        GTEST_SKIP() << "real meshes not present: " << e.what();
    }
}

}  // namespace
}  // namespace sdf
