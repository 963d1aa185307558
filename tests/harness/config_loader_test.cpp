// Config inheritance ("parent") and sweeps: merge rules, relative parent paths, cycles and
// their messages; cartesian products, labels, key paths into arrays, and bad sweeps.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "harness/config/config_loader.h"
#include "harness/config/json_reader.h"
#include "harness/config/sweep.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::Contains;
using test::error_of;

class Configs : public test::ScratchDirTest {
protected:
    Configs() : ScratchDirTest("sdf_config_loader_test") {}
};

// ---- merge rules ------------------------------------------------------------------------------

TEST(MergeConfig, ChildOverridesObjectsMergeArraysReplaceNullRemoves) {
    const json parent = {{"name", "base"},
                         {"sampler", {{"backend", "cpu"}, {"threads", 2}, {"nested", {{"a", 1}, {"b", 2}}}}},
                         {"lattices", {{{"type", "cc"}}, {{"type", "bcc"}}}},
                         {"render", {{"size", {512, 512}}}},
                         {"extra", 1}};
    const json child = {{"name", "child"},
                        {"sampler", {{"threads", 8}, {"nested", {{"b", 3}}}}},
                        {"lattices", {{{"type", "bcc"}}}},
                        {"render", nullptr},
                        {"new", true}};
    const json merged = merge_config(parent, child);
    EXPECT_EQ(merged, (json{{"name", "child"},
                            {"sampler", {{"backend", "cpu"}, {"threads", 8}, {"nested", {{"a", 1}, {"b", 3}}}}},
                            {"lattices", {{{"type", "bcc"}}}},
                            {"extra", 1},
                            {"new", true}}));
    // An object replaces a non-object and the other way round.
    EXPECT_EQ(merge_config({{"m", "dragon.obj"}}, {{"m", {{"shape", "box"}}}}), (json{{"m", {{"shape", "box"}}}}));
    EXPECT_EQ(merge_config({{"m", {{"shape", "box"}}}}, {{"m", "x.obj"}}), (json{{"m", "x.obj"}}));
}

// ---- load_config ------------------------------------------------------------------------------

TEST_F(Configs, ParentChainRelativeToEachFile) {
    write("base/root.json", R"({"kind": "reconstruction", "domain": {"margin": 0.2}, "metrics": {"seed": 1, "band": 2}})");
    write("base/study.json", R"(// comment
        {"parent": "root.json", "metrics": {"seed": 5}, "sampler": {"threads": 1}})");
    const std::string child = write("cfg/dragon.json", R"({"parent": "../base/study.json", "name": "dragon", "domain": {"margin": 0.1}})");
    const LoadedConfig c = load_config(child);
    EXPECT_EQ(c.merged, (json{{"kind", "reconstruction"},
                              {"domain", {{"margin", 0.1}}},
                              {"metrics", {{"seed", 5}, {"band", 2}}},
                              {"sampler", {{"threads", 1}}},
                              {"name", "dragon"}}));
    EXPECT_EQ(c.as_written.at("parent"), "../base/study.json");
    ASSERT_EQ(c.files.size(), 3u);
    EXPECT_EQ(fs::path(c.files[1]), fs::weakly_canonical(dir_ / "base/study.json"));
    EXPECT_EQ(fs::path(c.files[2]), fs::weakly_canonical(dir_ / "base/root.json"));
    EXPECT_TRUE(Contains(c.label(), "inheriting from"));
    EXPECT_TRUE(Contains(c.label(), "root.json"));
}

TEST_F(Configs, NoParentIsTheFileItself) {
    const std::string p = write("c.json", R"({"name": "x", "lattices": [1, 2]})");
    const LoadedConfig c = load_config(p);
    EXPECT_EQ(c.merged, c.as_written);
    EXPECT_EQ(c.label(), p);
}

TEST_F(Configs, ParentErrorsNameTheFileAndKey) {
    write("a.json", R"({"parent": "b.json", "name": "a"})");
    write("b.json", R"({"parent": "a.json"})");
    const std::string cycle = error_of([&] { load_config((dir_ / "a.json").string()); });
    EXPECT_TRUE(Contains(cycle, "inheritance cycle"));
    EXPECT_TRUE(Contains(cycle, "a.json -> "));
    write("c.json", R"({"parent": "missing.json"})");
    const std::string missing = error_of([&] { load_config((dir_ / "c.json").string()); });
    EXPECT_TRUE(Contains(missing, "c.json: key 'parent'"));
    EXPECT_TRUE(Contains(missing, "missing.json"));
    write("d.json", R"({"parent": 3})");
    EXPECT_TRUE(Contains(error_of([&] { load_config((dir_ / "d.json").string()); }), "got 3"));
    write("e.json", R"({"parent": "bad.json"})");
    write("bad.json", "{\n  \"x\": ,\n}");
    EXPECT_TRUE(Contains(error_of([&] { load_config((dir_ / "e.json").string()); }), "bad.json:2:"));
    write("f.json", R"({"parent": "arr.json"})");
    write("arr.json", "[1]");
    EXPECT_TRUE(Contains(error_of([&] { load_config((dir_ / "f.json").string()); }), "expected a JSON object"));
}

// ---- sweeps -----------------------------------------------------------------------------------

TEST(Sweep, NoSweepIsOnePoint) {
    const json c = {{"name", "x"}, {"a", 1}};
    const auto points = expand_sweep(c, "c.json", "x");
    ASSERT_EQ(points.size(), 1u);
    EXPECT_EQ(points[0].name, "x");
    EXPECT_EQ(points[0].config, c);
    EXPECT_TRUE(points[0].parameters.empty());
}

TEST(Sweep, CartesianProductNamedAfterParameters) {
    const json c = {{"name", "s"},
                    {"sampler", {{"precision", "float"}}},
                    {"lattices", {{{"type", "cc"}, {"resolution", {8, 8, 8}}}, {{"type", "bcc"}}}},
                    {"sweep", {{"sampler.precision", {"float", "double"}},
                               {"lattices[0].resolution", {{16, 16, 16}, {32, 32, 32}, {64, 64, 64}}}}}};
    const auto points = expand_sweep(c, "c.json", "s");
    ASSERT_EQ(points.size(), 6u);
    // Axes in key order ("lattices[0].resolution" < "sampler.precision"), the last fastest.
    EXPECT_EQ(points[0].name, "s-resolution_16x16x16-precision_float");
    EXPECT_EQ(points[1].name, "s-resolution_16x16x16-precision_double");
    EXPECT_EQ(points[5].name, "s-resolution_64x64x64-precision_double");
    EXPECT_EQ(points[5].config.at("lattices")[0].at("resolution"), json({64, 64, 64}));
    EXPECT_EQ(points[5].config.at("lattices")[1], json({{"type", "bcc"}}));
    EXPECT_EQ(points[5].config.at("sampler").at("precision"), "double");
    EXPECT_FALSE(points[5].config.contains("sweep"));
    EXPECT_EQ(points[2].parameters, (json{{"lattices[0].resolution", {32, 32, 32}}, {"sampler.precision", "float"}}));
}

TEST(Sweep, GivenLabelsAndCreatedObjects) {
    const json c = {{"name", "pawn"},
                    {"sweep", {{"lattices", {{"labels", {"33k", "200k"}}, {"values", {{1}, {2}}}}},
                               {"metrics.seed", {1, 2}}}}};
    const auto points = expand_sweep(c, "c.json", "pawn");
    ASSERT_EQ(points.size(), 4u);
    EXPECT_EQ(points[0].name, "pawn-33k-seed_1");
    EXPECT_EQ(points[3].name, "pawn-200k-seed_2");
    EXPECT_EQ(points[3].config.at("metrics").at("seed"), 2);  // "metrics" created on the way
    EXPECT_EQ(points[3].config.at("lattices"), json({2}));
}

TEST(Sweep, ObjectValuesWithoutLabelsAreNumbered) {
    const json c = {{"name", "x"}, {"sweep", {{"mesh", {{{"shape", "box"}}, {{"shape", "torus"}}}}}}};
    const auto points = expand_sweep(c, "c.json", "x");
    ASSERT_EQ(points.size(), 2u);
    EXPECT_EQ(points[0].name, "x-mesh_1");
    EXPECT_EQ(points[1].name, "x-mesh_2");
    EXPECT_EQ(sweep_value_label("a b/c"), "a_b_c");
    EXPECT_EQ(sweep_value_label(json{0.5, true}), "0.5xtrue");
    EXPECT_EQ(sweep_value_label(json{{"a", 1}}), "");
}

TEST(Sweep, BadSweepsNameTheKey) {
    struct Case {
        json sweep;
        std::string expect;
    };
    for (const Case& c : std::vector<Case>{
             {json::array(), "key 'sweep': expected an object"},
             {json::object(), "key 'sweep': expected an object"},
             {{{"a", json::array()}}, "'sweep.a': expected a non-empty array"},
             {{{"a", 3}}, "'sweep.a': expected a non-empty array"},
             {{{"lattices[5].type", {"cc"}}}, "'sweep.lattices[5].type': \"lattices\" has no entry [5]"},
             {{{"name.x", {"cc"}}}, "cannot be swept"},
             {{{"kind", {"speedup"}}}, "cannot be swept"},
             {{{"a..b", {1}}}, "'sweep.a..b'"},
             {{{"a", {{"values", {1, 2}}, {"labels", {"x"}}}}}, "one per value"},
             {{{"a", {{"values", {1, 2}}, {"labels", {"x", "x"}}}}}, "the label \"x\""},
             {{{"a", {{"values", {1}}, {"labels", {"../x"}}}}}, "labels of letters"},
             {{{"a", {{"valus", {1}}}}}, "unknown key 'valus'"},
             {{{"a", {1, 1}}}, "the label \"a_1\""},
             {{{"lattices.x", {1}}}, "not an object"},
         }) {
        const json cfg = {{"name", "x"}, {"lattices", {{{"type", "cc"}}}}, {"sweep", c.sweep}};
        const std::string msg = error_of([&] { expand_sweep(cfg, "c.json", "x"); });
        EXPECT_TRUE(Contains(msg, "c.json")) << c.sweep.dump();
        EXPECT_TRUE(Contains(msg, c.expect)) << c.sweep.dump();
    }
}

TEST(Sweep, SetAtKeyPath) {
    json j = {{"a", {{"b", {1, 2, {{"c", 0}}}}}}};
    set_at_key_path(j, "a.b[2].c", 5);
    EXPECT_EQ(j["a"]["b"][2]["c"], 5);
    set_at_key_path(j, "a.new.deep", "x");
    EXPECT_EQ(j["a"]["new"]["deep"], "x");
    set_at_key_path(j, "a.b[0]", json({1, 2}));
    EXPECT_EQ(j["a"]["b"][0], json({1, 2}));
    EXPECT_THROW(set_at_key_path(j, "", 1), std::invalid_argument);
    EXPECT_THROW(set_at_key_path(j, "a.", 1), std::invalid_argument);
    EXPECT_THROW(set_at_key_path(j, "a[0]", 1), std::invalid_argument);  // "a" is an object
    EXPECT_THROW(set_at_key_path(j, "a.b[0]x", 1), std::invalid_argument);
}

}  // namespace
}  // namespace sdf
