// run-experiment end to end: configs/ci_smoke.json and its committed baseline, a perturbed
// result failing the check, the field cache across runs and kinds (and --no-cache), sweeps
// with inheritance, the analytic and speedup kinds at tiny sizes, and baselines from clean runs
// only. The report (scripts/make-report) is tested with pytest: tests/python.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/build_config.h"
#include "harness_test_util.h"

#ifndef RUN_EXPERIMENT_EXE
#error "RUN_EXPERIMENT_EXE must be defined by CMake"
#endif

namespace sdf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::Contains;
using test::quote;
using test::read_json;
using test::ShellResult;

class E2e : public test::ScratchDirTest {
protected:
    E2e() : ScratchDirTest("sdf_e2e_test") {}

    ShellResult shell(const std::string& command) const {
        return test::run_in(dir_, "SDF_CACHE_DIR=" + quote(at("cache")) + " " + command);
    }
    ShellResult run(const std::string& args) const { return shell(quote(RUN_EXPERIMENT_EXE) + " " + args); }
    /// The single run directory under out/<name>/.
    fs::path only_run(const std::string& name, const std::string& root = "out") const {
        std::vector<fs::path> runs;
        for (const auto& e : fs::directory_iterator(dir_ / root / name)) runs.push_back(e.path());
        EXPECT_EQ(runs.size(), 1u) << name;
        return runs.empty() ? fs::path() : runs[0];
    }
};

const std::string kSource = SDF_SOURCE_DIR;

/// A tiny reconstruction config on the procedural box.
json tiny_study(const std::string& name) {
    return {{"name", name},
            {"kind", "reconstruction"},
            {"mesh", {{"shape", "sphere"}, {"subdivisions", 1}}},
            {"lattices", {{{"type", "cc"}, {"resolution", {6, 6, 6}}}, {{"type", "bcc"}, {"resolution", {5, 5, 10}}}}},
            // The CPU named: the dry-run lines below name the sampler (the default is "auto").
            {"sampler", {{"backend", "cpu"}, {"threads", 1}, {"progress", false}}},
            {"metrics", {{"domain_probes", 200}, {"band_probes", 200}}}};
}

// ---- the CI-sized config and its committed baseline ----------------------------------------

TEST_F(E2e, CiSmokeRunPassesItsCommittedBaseline) {
    const ShellResult r = run(quote(kSource + "/configs/ci_smoke.json") + " --output-root out --check --quiet");
    EXPECT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out, "check of ci_smoke/"));
    EXPECT_TRUE(Contains(r.out, "PASSED"));
    const fs::path run_dir = only_run("ci_smoke");
    const json metrics = read_json(run_dir / "metrics.json");
    EXPECT_EQ(metrics.at("reconstructions").size(), 7u);
    EXPECT_GE(metrics.at("regression").size(), 40u);
    const json manifest = read_json(run_dir / "manifest.json");
    for (const char* key : {"run_id", "config", "provenance", "started", "finished", "inputs"}) EXPECT_TRUE(manifest.contains(key)) << key;
    EXPECT_TRUE(manifest.at("provenance").at("git").contains("dirty"));
    EXPECT_TRUE(manifest.at("provenance").at("build").contains("cxx_flags"));
    EXPECT_TRUE(manifest.at("provenance").at("load_average").contains("start"));
    EXPECT_TRUE(manifest.at("provenance").at("load_average").contains("end"));
    EXPECT_TRUE(manifest.at("config").contains("resolved"));
    EXPECT_EQ(manifest.at("inputs").at("fields").size(), 2u);
    // The run holds the fields it measured (issue 13), named beside their cache keys.
    for (const json& f : manifest.at("inputs").at("fields")) {
        const fs::path header = run_dir / f.at("file").get<std::string>();
        ASSERT_TRUE(fs::exists(header)) << f.dump();
        EXPECT_EQ(read_json(header).at("lattice").at("points"), metrics.at("regression")
                      .at("lattices/" + f.at("label").get<std::string>() + "/points").at("value")) << f.dump();
    }
}

TEST_F(E2e, PerturbedResultFailsTheCheckReadably) {
    ASSERT_EQ(run(quote(kSource + "/configs/ci_smoke.json") + " --output-root out --quiet").code, 0);
    const fs::path run_dir = only_run("ci_smoke");
    const std::string baseline = kSource + "/results/baselines/ci_smoke.json";
    EXPECT_EQ(run("--check-run " + quote(run_dir.string()) + " --baseline " + quote(baseline)).code, 0);
    // Make one error 50 % worse.
    json metrics = read_json(run_dir / "metrics.json");
    const std::string key = "cc-14x14x14/catmull_rom/fd/domain_rms";
    ASSERT_TRUE(metrics.at("regression").contains(key));
    const double before = metrics["regression"][key]["value"];
    metrics["regression"][key]["value"] = before * 1.5;
    fs::permissions(run_dir / "metrics.json", fs::perms::owner_write, fs::perm_options::add);
    std::ofstream(run_dir / "metrics.json") << metrics.dump(2);
    const ShellResult r = run("--check-run " + quote(run_dir.string()));  // the baseline named by the config
    EXPECT_EQ(r.code, 3) << r.out << r.err;
    EXPECT_TRUE(Contains(r.out, "FAIL  " + key)) << r.out;
    EXPECT_TRUE(Contains(r.out, "(+50%)")) << r.out;
    EXPECT_TRUE(Contains(r.out, "FAILED:")) << r.out;
    EXPECT_TRUE(Contains(r.out, "1 outside")) << r.out;
}

// ---- the field cache -------------------------------------------------------------------------

TEST_F(E2e, FieldsAreCachedAcrossRunsAndKindsAndNoCacheResamples) {
    write("a.json", tiny_study("a").dump());
    json sampling = tiny_study("s");
    sampling["kind"] = "sampling";
    sampling.erase("metrics");
    sampling["lattices"] = {{{"type", "bcc"}, {"resolution", {5, 5, 10}}}};
    write("s.json", sampling.dump());

    // The sampling kind fills the BCC entry; the reconstruction kind then finds it.
    ASSERT_EQ(run("s.json --output-root out --quiet").code, 0);
    const ShellResult dry = run("a.json --output-root out --dry-run");
    ASSERT_EQ(dry.code, 0) << dry.err;
    EXPECT_TRUE(Contains(dry.out, "field cc-6x6x6: cc 6x6x6, 216 points, cpu/bvh: to sample")) << dry.out;
    EXPECT_TRUE(Contains(dry.out, "field bcc-5x5x10: bcc 5x5x10, 189 points, cpu/bvh: cached")) << dry.out;
    const ShellResult first = run("a.json --output-root out --quiet");
    ASSERT_EQ(first.code, 0) << first.err;
    EXPECT_TRUE(Contains(first.out, "cc-6x6x6 (6x6x6, 216 points): sampled")) << first.out;
    EXPECT_TRUE(Contains(first.out, "bcc-5x5x10 (5x5x10, 189 points): from the cache")) << first.out;
    EXPECT_TRUE(Contains(first.out, "probes: exact distances computed")) << first.out;
    // A second run samples nothing and gets the same numbers.
    const ShellResult second = run("a.json --output-root out2 --quiet");
    ASSERT_EQ(second.code, 0) << second.err;
    EXPECT_FALSE(Contains(second.out, "sampled in")) << second.out;
    EXPECT_TRUE(Contains(second.out, "probes from the cache")) << second.out;
    const json m1 = read_json(only_run("a") / "metrics.json");
    const json m2 = read_json(only_run("a", "out2") / "metrics.json");
    EXPECT_EQ(m1.at("regression"), m2.at("regression"));
    EXPECT_TRUE(m2.at("lattices")[0].at("from_cache").get<bool>());
    // --no-cache samples everything again and leaves the cache alone.
    const ShellResult dry_nc = run("a.json --output-root out3 --dry-run --no-cache");
    EXPECT_TRUE(Contains(dry_nc.out, "to sample (--no-cache)")) << dry_nc.out;
    const ShellResult nc = run("a.json --output-root out3 --no-cache --quiet");
    ASSERT_EQ(nc.code, 0) << nc.err;
    EXPECT_TRUE(Contains(nc.out, "cc-6x6x6 (6x6x6, 216 points): sampled")) << nc.out;
    EXPECT_TRUE(Contains(nc.out, "bcc-5x5x10 (5x5x10, 189 points): sampled")) << nc.out;
    const json m3 = read_json(only_run("a", "out3") / "metrics.json");
    EXPECT_FALSE(m3.at("lattices")[0].at("from_cache").get<bool>());
    EXPECT_EQ(m1.at("regression"), m3.at("regression"));
    EXPECT_FALSE(read_json(only_run("a", "out3") / "manifest.json").at("cache").at("used").get<bool>());
    // --cache-dir chooses another cache: nothing there yet.
    EXPECT_TRUE(Contains(run("a.json --dry-run --cache-dir " + quote(at("other"))).out, "bcc-5x5x10: bcc 5x5x10, 189 points, cpu/bvh: to sample"));
}

// ---- sweeps and inheritance ------------------------------------------------------------------

TEST_F(E2e, SweepWithParentRunsEveryPointInOneRunDirectory) {
    json parent = tiny_study("unused");
    parent.erase("name");
    write("common/base.json", parent.dump());
    write("cfg/sweep.json", json{{"parent", "../common/base.json"},
                                 {"name", "sw"},
                                 {"sweep", {{"lattices[0].resolution", {{5, 5, 5}, {7, 7, 7}}}}},
                                 {"reconstructions", {{{"lattice", "cc"}, {"interpolator", "catmull_rom"}}}}}
                                .dump());
    const ShellResult dry = run("cfg/sweep.json --output-root out --dry-run");
    ASSERT_EQ(dry.code, 0) << dry.err;
    EXPECT_TRUE(Contains(dry.out, "2 runs")) << dry.out;
    EXPECT_TRUE(Contains(dry.out, "[1/2] sw-resolution_5x5x5")) << dry.out;
    EXPECT_TRUE(Contains(dry.out, "[2/2] sw-resolution_7x7x7")) << dry.out;
    EXPECT_TRUE(Contains(dry.out, "inheriting from")) << dry.out;
    const ShellResult r = run("cfg/sweep.json --output-root out --quiet");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(Contains(r.out, "[2/2] sw-resolution_7x7x7"));
    const fs::path run_dir = only_run("sw");
    const json metrics = read_json(run_dir / "metrics.json");
    ASSERT_EQ(metrics.at("points").size(), 2u);
    EXPECT_EQ(metrics["points"][0].at("name"), "sw-resolution_5x5x5");
    EXPECT_EQ(metrics["points"][1].at("parameters").at("lattices[0].resolution"), json({7, 7, 7}));
    EXPECT_EQ(metrics["points"][1].at("metrics").at("reconstructions").size(), 1u);
    EXPECT_TRUE(metrics.at("regression").contains("sw-resolution_7x7x7/cc-7x7x7/catmull_rom/fd/domain_rms"));
    const json manifest = read_json(run_dir / "manifest.json");
    ASSERT_EQ(manifest.at("points").size(), 2u);
    EXPECT_EQ(manifest["points"][1].at("resolved").at("lattices")[0].at("resolution"), json({7, 7, 7}));
    EXPECT_EQ(manifest["points"][1].at("resolved").at("metrics").at("band"), 1.0);  // a default, filled in
    EXPECT_EQ(manifest.at("config").at("files").size(), 2u);
    EXPECT_TRUE(manifest.at("config").at("as_written").contains("parent"));
    EXPECT_FALSE(manifest.at("config").at("merged").contains("parent"));
}

TEST_F(E2e, ReconstructionStudyRendersTheThesisGridWithImageMetrics) {
    json cfg = tiny_study("render_tiny");
    cfg["mesh"] = {{"shape", "pawn"}};
    cfg["lattices"] = {{{"type", "cc"}, {"resolution", {16, 16, 16}}}, {{"type", "bcc"}, {"resolution", {13, 13, 26}}}};
    cfg["render"] = {{"size", {48, 48}}, {"views", {"front"}}, {"backend", "cpu"}};
    write("render.json", cfg.dump());
    const ShellResult dry = run("render.json --output-root out --dry-run");
    ASSERT_EQ(dry.code, 0) << dry.err;
    EXPECT_TRUE(Contains(dry.out, "render front at 48x48")) << dry.out;
    const ShellResult r = run("render.json --output-root out --quiet");
    ASSERT_EQ(r.code, 0) << r.err;
    const fs::path run_dir = only_run("render_tiny");
    const json metrics = read_json(run_dir / "metrics.json");
    const json& view = metrics.at("render").at("views").at("front");
    ASSERT_EQ(view.at("panels").size(), 5u);  // A..E of the thesis's figures
    for (const json& panel : view["panels"]) {
        // Every panel sees the pawn: most reference pixels are hit by the reconstruction too.
        const json& m = panel.at("metrics");
        EXPECT_GT(m.at("hit_both").get<int64_t>(), 200) << panel.dump();
        EXPECT_LT(m.at("coverage_mismatch_fraction").get<double>(), 0.05) << panel.dump();
    }
    EXPECT_TRUE(fs::is_regular_file(run_dir / view.at("grid_file").get<std::string>()));
    EXPECT_TRUE(metrics.at("regression").contains("render/front/B_bcc_cubic_true/normal_angle_mean_deg"));
}

TEST_F(E2e, EveryFilterWithItsCostAndConfiguredGridPanels) {
    json cfg = tiny_study("all_tiny");
    cfg["mesh"] = {{"shape", "pawn"}};
    cfg["lattices"] = {{{"type", "cc"}, {"resolution", {12, 12, 12}}}, {{"type", "bcc"}, {"resolution", {10, 10, 20}}}};
    cfg["reconstructions"] = "all";
    cfg["render"] = {{"size", {32, 32}}, {"views", {"front"}}, {"backend", "cpu"},
                     {"panels", {"bcc_cubic/true", "bcc_box_quintic"}}};
    write("all.json", cfg.dump());
    const ShellResult dry = run("all.json --output-root out --dry-run");
    ASSERT_EQ(dry.code, 0) << dry.err;
    EXPECT_TRUE(Contains(dry.out, "reconstruct cc-12x12x12/cc_bspline3/fd")) << dry.out;
    EXPECT_TRUE(Contains(dry.out, "reconstruct bcc-10x10x20/bcc_box_quintic_approx/fd")) << dry.out;
    EXPECT_TRUE(Contains(dry.out, "panels A bcc_cubic/true, B bcc_box_quintic/fd")) << dry.out;
    const ShellResult r = run("all.json --output-root out --quiet");
    ASSERT_EQ(r.code, 0) << r.err;
    const json metrics = read_json(only_run("all_tiny") / "metrics.json");
    // 5 CC filters (tricubic_lm twice) and 9 BCC ones (bcc_cubic and bcc_cubic_c0 twice)
    ASSERT_EQ(metrics.at("reconstructions").size(), 14u);
    const int64_t probes = metrics.at("probes").at("domain").get<int64_t>() + metrics["probes"].at("band_placed").get<int64_t>();
    for (const json& rec : metrics["reconstructions"]) {
        EXPECT_GT(rec.at("eval_ns_per_point").get<double>(), 0.0) << rec.at("id");
        EXPECT_GE(rec.at("prepare_seconds").get<double>(), 0.0) << rec.at("id");
        EXPECT_EQ(rec.at("timed_points").get<int64_t>(), probes) << rec.at("id");  // every probe (fewer than 2^16)
        EXPECT_LT(rec.at("errors").at("band").at("rms").get<double>(), 0.5) << rec.at("id");
    }
    const json& view = metrics.at("render").at("views").at("front");
    ASSERT_EQ(view.at("panels").size(), 2u);
    EXPECT_EQ(view["panels"][1].at("label"), "B  BCC quintic box spline, interpolating (10x10x20)");
    EXPECT_TRUE(metrics.at("regression").contains("render/front/B_bcc_box_quintic_fd/normal_angle_mean_deg"));

    // Panels on a lattice type the study lacks: refused before anything runs, naming the panel.
    cfg["lattices"] = {{{"type", "bcc"}, {"resolution", {10, 10, 20}}}};
    cfg["render"]["panels"] = {"bcc_box_quintic", "cc_bspline3"};
    write("cc_missing.json", cfg.dump());
    const ShellResult bad = run("cc_missing.json --output-root out --dry-run");
    EXPECT_NE(bad.code, 0);
    EXPECT_TRUE(Contains(bad.err, "the panels need a CC lattice in \"lattices\" (panel B: cc_bspline3/fd)")) << bad.err;
}

// ---- the other kinds at tiny sizes -------------------------------------------------------------

TEST_F(E2e, AnalyticConvergencePaddedLatticesAndCosts) {
    write("pad.json", json{{"name", "pad_tiny"},
                           {"kind", "analytic"},
                           {"threads", 1},
                           {"convergence", {{"function", "marschner_lobb"}, {"samples", {4000}},
                                            {"interpolators", {"cc_bspline3", "bcc_box_quintic", "bcc_linear"}},
                                            {"probes_per_axis", 8}, {"margin", 0}, {"padding", 4}, {"probes", "random"}}}}
                          .dump());
    const ShellResult r = run("pad.json --output-root out --quiet");
    ASSERT_EQ(r.code, 0) << r.err;
    const json m = read_json(only_run("pad_tiny") / "metrics.json");
    for (const json& curve : m.at("convergence").at("curves")) {
        const json& p = curve.at("points").at(0);
        EXPECT_EQ(p.at("padding_spacings"), 4);
        EXPECT_EQ(p.at("random_probes"), true);
        // The samples counted are those over [-1,1]^3 (16^3 CC, 13^3 + 12^3 BCC), not the padding's.
        EXPECT_EQ(p.at("lattice_points"), curve.at("lattice_type") == "cc" ? 4096 : 3925) << curve.at("id");
        // Padding beyond the margin: every filter is probed over all of [-1,1]^3.
        EXPECT_EQ(p.at("probe_box"), json({{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}})) << curve.at("id");
        EXPECT_GT(p.at("eval_ns_per_point").get<double>(), 0.0);
        EXPECT_EQ(p.at("timed_points"), 512);
    }
    write("pad_bad.json", json{{"name", "b"}, {"kind", "analytic"}, {"convergence", {{"padding", 40}}}}.dump());
    const ShellResult bad = run("pad_bad.json --dry-run");
    EXPECT_NE(bad.code, 0);
    EXPECT_TRUE(Contains(bad.err, "'convergence.padding'")) << bad.err;
}

TEST_F(E2e, AnalyticKindTinyTable41AndConvergence) {
    write("ml.json", json{{"name", "ml_tiny"},
                          {"kind", "analytic"},
                          {"threads", 1},
                          {"table_4_1", {{"resolution", {10, 10, 20}}, {"probes_per_axis", 12}}},
                          {"convergence", {{"samples", {2000, 4000}}, {"interpolators", {"catmull_rom", "bcc_cubic/fd"}},
                                           {"probes_per_axis", 8}}}}
                         .dump());
    const ShellResult r = run("ml.json --output-root out --quiet");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(Contains(r.out, "thesis 8.725 / 8.939"));
    const json m = read_json(only_run("ml_tiny") / "metrics.json");
    EXPECT_EQ(m.at("table_4_1").at("lattice"), "10x10x20");
    EXPECT_GT(m.at("table_4_1").at("plain").at("rms").get<double>(), 0.0);
    EXPECT_EQ(m.at("table_4_1").at("thesis").at("plain"), 8.939);
    ASSERT_EQ(m.at("convergence").at("curves").size(), 2u);
    EXPECT_EQ(m["convergence"]["curves"][1].at("id"), "bcc_cubic/fd");
    EXPECT_EQ(m["convergence"]["curves"][1].at("points").size(), 2u);
    EXPECT_TRUE(m.at("regression").contains("convergence/catmull_rom/fd/2000/rms"));
    write("small.json", json{{"name", "s"}, {"kind", "analytic"}, {"convergence", {{"samples", {200}}}}}.dump());
    const ShellResult small = run("small.json --dry-run");
    EXPECT_NE(small.code, 0);
    EXPECT_TRUE(Contains(small.err, "'convergence.samples': 200 samples give trilinear/fd a 6^3 lattice")) << small.err;
    // Errors name the key.
    write("bad.json", json{{"name", "b"}, {"kind", "analytic"}, {"convergence", {{"interpolators", {"bcc_cubic/fd_weird"}}}}}.dump());
    const ShellResult bad = run("bad.json --dry-run");
    EXPECT_NE(bad.code, 0);
    EXPECT_TRUE(Contains(bad.err, "'convergence.interpolators'")) << bad.err;
}

TEST_F(E2e, SpeedupKindReportsGpuBackendsAsUnavailableWithoutAGpu) {
    write("sp.json", json{{"name", "sp"},
                          {"kind", "speedup"},
                          {"cases", {{{"label", "bunny"}, {"mesh", {{"shape", "sphere"}, {"subdivisions", 1}}}, {"samples", {64}}}}},
                          {"lattice_types", {"cc", "bcc"}},
                          {"backends", {{{"name", "cpu_1"}, {"backend", "cpu"}, {"method", "brute_force"}, {"threads", 1}, {"max_points", 16}},
                                        {{"name", "cpu_all"}, {"backend", "cpu"}, {"method", "brute_force"}},
                                        {{"name", "gpu_tuned"}, {"backend", "cuda"}, {"method", "brute_force"}, {"kernel", "tuned"}}}},
                          {"repetitions", 1}}
                         .dump());
    const ShellResult r = run("sp.json --output-root out --quiet");
    ASSERT_EQ(r.code, 0) << r.err;
    const json m = read_json(only_run("sp") / "metrics.json");
    ASSERT_EQ(m.at("rows").size(), 2u);
    EXPECT_EQ(m.at("meshes").at("bunny").at("thesis_table_3_1").at("triangles"), 69666);
    const json& backends = m["rows"][0].at("backends");
    EXPECT_EQ(backends[0].at("status"), "ok");
    EXPECT_TRUE(backends[0].at("extrapolated").get<bool>());
    EXPECT_TRUE(m.at("regression").contains("bunny/64/cc/cpu_all/speedup"));
#if !SDF_HAVE_CUDA
    EXPECT_TRUE(Contains(backends[2].at("status").get<std::string>(), "unavailable"));
    EXPECT_FALSE(backends[2].contains("seconds_median"));
    EXPECT_FALSE(m.at("regression").contains("bunny/64/cc/gpu_tuned/speedup"));
#endif
    write("bad.json", json{{"name", "b"}, {"kind", "speedup"}, {"cases", {{{"label", "x"}, {"mesh", "shape:box"}, {"samples", {64}}}}},
                           {"backends", {{{"name", "a"}}}}, {"reference", "b"}}
                          .dump());
    EXPECT_TRUE(Contains(run("bad.json --dry-run").err, "'reference'"));
}

// ---- baselines ---------------------------------------------------------------------------------

TEST_F(E2e, BaselinesOnlyFromCleanRuns) {
    write("a.json", tiny_study("a").dump());
    ASSERT_EQ(run("a.json --output-root out --quiet").code, 0);
    const fs::path run_dir = only_run("a");
    json manifest = read_json(run_dir / "manifest.json");
    fs::permissions(run_dir / "manifest.json", fs::perms::owner_write, fs::perm_options::add);
    manifest["provenance"]["git"] = {{"commit", "0123abcd"}, {"dirty", true}};  // also where git is absent
    std::ofstream(run_dir / "manifest.json") << manifest.dump(2);
    const ShellResult dirty = run("--write-baseline " + quote(run_dir.string()) + " --baseline b/a.json");
    EXPECT_EQ(dirty.code, 1);
    EXPECT_TRUE(Contains(dirty.err, "dirty work tree")) << dirty.err;
    EXPECT_FALSE(fs::exists(dir_ / "b/a.json"));
    manifest["provenance"]["git"] = {{"commit", "0123abcd"}, {"dirty", false}};
    std::ofstream(run_dir / "manifest.json") << manifest.dump(2);
    const ShellResult clean = run("--write-baseline " + quote(run_dir.string()) + " --baseline b/a.json");
    ASSERT_EQ(clean.code, 0) << clean.err;
    EXPECT_TRUE(Contains(clean.out, "baseline b/a.json"));
    EXPECT_EQ(read_json(dir_ / "b/a.json").at("made_from").at("git_commit"), "0123abcd");
    EXPECT_TRUE(Contains(run("--write-baseline " + quote(run_dir.string()) + " --baseline b/a.json").err, "already exists"));
    EXPECT_EQ(run("--write-baseline " + quote(run_dir.string()) + " --baseline b/a.json --force").code, 0);
    // A new run checks against it.
    const ShellResult check = run("a.json --output-root out2 --check --baseline b/a.json --quiet");
    EXPECT_EQ(check.code, 0) << check.out << check.err;
    EXPECT_TRUE(Contains(check.out, "PASSED"));
    // Without a baseline file: a clear error.
    const ShellResult none = run("a.json --output-root out3 --check --baseline b/none.json --quiet");
    EXPECT_EQ(none.code, 1);
    EXPECT_TRUE(Contains(none.err, "no baseline at b/none.json"));
    EXPECT_TRUE(Contains(none.err, "--write-baseline"));
    // Modes are exclusive.
    EXPECT_EQ(run("a.json --check-run " + quote(run_dir.string())).code, 2);  // a command-line error
}

}  // namespace
}  // namespace sdf
