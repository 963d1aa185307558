// Regression checks against baselines: tolerances both ways, speedup floors only on the
// baseline's machine kind, exact counts, missing and new metrics, readable messages; making
// baselines only from clean runs.
#include <gtest/gtest.h>

#include <string>

#include "harness/check/regression_check.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

using nlohmann::json;
using test::Contains;

json manifest(bool dirty = false, const std::string& cpu = "CPU A", const json& gpu = nullptr) {
    return {{"run_id", "20261121T000000.000Z-abcdef12"},
            {"name", "study"},
            {"kind", "reconstruction"},
            {"finished", "2026-11-21T00:00:01Z"},
            {"config", {{"sha256", "0123456789abcdef"}}},
            {"provenance", {{"git", {{"commit", "feedbeef"}, {"dirty", dirty}}},
                            {"cpu", {{"model", cpu}}},
                            {"gpu", gpu.is_null() ? json(nullptr) : json{{"name", gpu}}}}}};
}

json metrics(double rms = 0.01, double speedup = 100, int points = 512) {
    return {{"regression", {{"cc/catmull_rom/fd/domain_rms", {{"value", rms}, {"kind", "error"}}},
                            {"dragon/262144/cc/gpu_tuned/speedup", {{"value", speedup}, {"kind", "speedup"}}},
                            {"lattices/cc/points", {{"value", points}, {"kind", "exact"}}}}}};
}

TEST(MakeBaseline, FromACleanRunWithDefaultTolerances) {
    const json b = make_baseline(manifest(false, "CPU A", "GPU X"), metrics());
    EXPECT_EQ(b.at("format"), "sdf-baseline");
    EXPECT_EQ(b.at("name"), "study");
    EXPECT_EQ(b.at("made_from").at("git_commit"), "feedbeef");
    EXPECT_EQ(b.at("machine"), (json{{"cpu", "CPU A"}, {"gpu", "GPU X"}, {"cpu_target", "unrecorded"}}));
    const json& m = b.at("metrics");
    EXPECT_EQ(m.at("cc/catmull_rom/fd/domain_rms").at("relative"), 0.01);
    EXPECT_DOUBLE_EQ(m.at("dragon/262144/cc/gpu_tuned/speedup").at("floor").get<double>(), 80.0);
    EXPECT_EQ(m.at("lattices/cc/points").at("kind"), "exact");
}

TEST(MakeBaseline, RefusesDirtyOrUnknownRunsAndEmptyMetrics) {
    try {
        make_baseline(manifest(true), metrics());
        FAIL() << "a dirty run became a baseline";
    } catch (const std::exception& e) {
        EXPECT_TRUE(Contains(e.what(), "dirty work tree"));
        EXPECT_TRUE(Contains(e.what(), "feedbeef"));
    }
    json unknown = manifest();
    unknown["provenance"]["git"]["commit"] = "unknown";
    EXPECT_ANY_THROW(make_baseline(unknown, metrics()));
    EXPECT_ANY_THROW(make_baseline(manifest(), json::object()));
}

TEST(CheckRun, SameMetricsPass) {
    const json b = make_baseline(manifest(false, "CPU A", "GPU X"), metrics());
    const CheckResult r = check_run(manifest(true, "CPU A", "GPU X"), metrics(), b, "results/baselines/study.json");
    EXPECT_TRUE(r.passed()) << r.text();
    EXPECT_EQ(r.ok, 3);
    EXPECT_TRUE(Contains(r.text(), "PASSED: 3 of 3 metrics within tolerance"));
    EXPECT_TRUE(Contains(r.text(), "against results/baselines/study.json"));
}

TEST(CheckRun, ErrorsWithinToleranceBothWays) {
    const json b = make_baseline(manifest(), metrics(0.01));
    EXPECT_TRUE(check_run(manifest(), metrics(0.0100999), b, "b").passed());
    EXPECT_TRUE(check_run(manifest(), metrics(0.0099001), b, "b").passed());
    const CheckResult worse = check_run(manifest(), metrics(0.0102), b, "b.json");
    EXPECT_FALSE(worse.passed());
    EXPECT_EQ(worse.failed, 1);
    const std::string t = worse.text();
    EXPECT_TRUE(Contains(t, "FAIL  cc/catmull_rom/fd/domain_rms = 0.0102, baseline 0.01 (+2%)")) << t;
    EXPECT_TRUE(Contains(t, "allowed +/-0.0001")) << t;
    EXPECT_TRUE(Contains(t, "FAILED: 2 of 3 metrics within tolerance, 1 outside")) << t;
    const CheckResult better = check_run(manifest(), metrics(0.005), b, "b");
    EXPECT_FALSE(better.passed());
    EXPECT_TRUE(Contains(better.text(), "lower than the baseline")) << better.text();
    json nan_metrics = metrics();
    nan_metrics["regression"]["cc/catmull_rom/fd/domain_rms"]["value"] = std::nan("");
    EXPECT_FALSE(check_run(manifest(), nan_metrics, b, "b").passed());
}

TEST(CheckRun, SpeedupFloorOnlyOnTheSameMachineKind) {
    const json b = make_baseline(manifest(false, "CPU A", "GPU X"), metrics(0.01, 100));
    EXPECT_TRUE(check_run(manifest(false, "CPU A", "GPU X"), metrics(0.01, 85), b, "b").passed());
    const CheckResult slow = check_run(manifest(false, "CPU A", "GPU X"), metrics(0.01, 70), b, "b");
    EXPECT_FALSE(slow.passed());
    EXPECT_TRUE(Contains(slow.text(), "dragon/262144/cc/gpu_tuned/speedup = 70, below the floor 80")) << slow.text();
    // Another GPU (or none): reported as not comparable, not failed.
    const CheckResult other = check_run(manifest(false, "CPU A", "GPU Y"), metrics(0.01, 5), b, "b");
    EXPECT_TRUE(other.passed()) << other.text();
    EXPECT_EQ(other.not_comparable, 1);
    EXPECT_TRUE(Contains(other.text(), "not comparable")) << other.text();
    EXPECT_TRUE(Contains(other.text(), "GPU \"GPU Y\"")) << other.text();
    EXPECT_TRUE(Contains(other.text(), "1 not comparable (other machine)")) << other.text();
    EXPECT_TRUE(check_run(manifest(false, "CPU B", "GPU X"), metrics(0.01, 5), b, "b").passed());
}

TEST(CheckRun, ExactMissingAndNewMetrics) {
    const json b = make_baseline(manifest(), metrics());
    EXPECT_FALSE(check_run(manifest(), metrics(0.01, 100, 513), b, "b").passed());
    json fewer = metrics();
    fewer["regression"].erase("lattices/cc/points");
    fewer["regression"]["brand/new"] = {{"value", 1.0}, {"kind", "error"}};
    const CheckResult r = check_run(manifest(), fewer, b, "b");
    EXPECT_FALSE(r.passed());
    EXPECT_EQ(r.missing, 1);
    EXPECT_EQ(r.added, 1);
    EXPECT_TRUE(Contains(r.text(), "lattices/cc/points: in the baseline but missing from this run"));
    EXPECT_TRUE(Contains(r.text(), "new   brand/new"));
    json other_config = manifest();
    other_config["config"]["sha256"] = "ffffffffffff";
    EXPECT_TRUE(Contains(check_run(other_config, metrics(), b, "b").text(), "config differs"));
    EXPECT_ANY_THROW(check_run(manifest(), metrics(), json{{"format", "other"}}, "b"));
}

}  // namespace
}  // namespace sdf

namespace sdf {
namespace {

// Issue 11: a baseline that checks nothing, or that the check cannot read as written, is an
// error, never a pass.
TEST(CheckRun, EmptyOrUnreadableBaselinesAreErrors) {
    json base = make_baseline(manifest(), metrics());
    json empty = base;
    empty["metrics"] = json::object();
    EXPECT_TRUE(Contains(test::error_of([&] { check_run(manifest(), metrics(), empty, "b.json"); }),
                         "b.json: key 'metrics': expected an object with at least one metric"));
    json missing = base;
    missing.erase("metrics");
    EXPECT_TRUE(Contains(test::error_of([&] { check_run(manifest(), metrics(), missing, "b.json"); }), "key 'metrics'"));
    json unknown = base;
    unknown["metrics"]["lattices/cc/points"]["kind"] = "exakt";
    EXPECT_TRUE(Contains(test::error_of([&] { check_run(manifest(), metrics(), unknown, "b.json"); }),
                         "b.json: key 'metrics.lattices/cc/points': unknown kind \"exakt\""));
    json no_value = base;
    no_value["metrics"]["lattices/cc/points"].erase("value");
    EXPECT_TRUE(Contains(test::error_of([&] { check_run(manifest(), metrics(), no_value, "b.json"); }),
                         "expected an object with a numeric \"value\""));
    json text_tolerance = base;
    text_tolerance["metrics"]["cc/catmull_rom/fd/domain_rms"]["relative"] = "1%";
    EXPECT_TRUE(Contains(test::error_of([&] { check_run(manifest(), metrics(), text_tolerance, "b.json"); }),
                         "key 'relative': expected a number"));
    EXPECT_TRUE(check_run(manifest(), metrics(), base, "b.json").passed());
}

}  // namespace
}  // namespace sdf
