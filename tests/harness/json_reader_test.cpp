// read_json_file() and JsonReader: every config error names the file, the key path and what
// was expected; malformed JSON names file:line:column; unknown keys are rejected with the
// nearest known key suggested. Truth is written by hand here (line/column counted in the
// literal texts, edit distances from the textbook examples).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "harness/config/json_reader.h"
#include "harness_test_util.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::Contains;

/// Runs `f` and returns the ConfigError message; fails the test when nothing is thrown.
template <typename F>
std::string config_error(F&& f) {
    try {
        f();
    } catch (const ConfigError& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "threw a non-ConfigError: " << e.what();
        return e.what();
    }
    ADD_FAILURE() << "no ConfigError was thrown";
    return {};
}

class JsonFile : public test::ScratchDirTest {
protected:
    JsonFile() : ScratchDirTest("sdf_json_reader_test") {}
};

// ---- read_json_file -------------------------------------------------------------------

TEST_F(JsonFile, ParsesValidJsonWithLineAndBlockComments) {
    const std::string path = write("c.json",
                                   "// a config\n"
                                   "{\n"
                                   "  \"name\": \"x\", /* inline */\n"
                                   "  \"n\": 3 // trailing\n"
                                   "}\n");
    const json j = read_json_file(path);
    EXPECT_EQ(j.at("name"), "x");
    EXPECT_EQ(j.at("n"), 3);
}

// Line 3 is `  "b": ,` : the ',' is column 8.
TEST_F(JsonFile, MalformedJsonNamesFileLineAndColumn) {
    const std::string path = write("bad.json", "{\n  \"a\": 1,\n  \"b\": ,\n}\n");
    const std::string msg = config_error([&] { read_json_file(path); });
    EXPECT_TRUE(Contains(msg, path + ":3:8:")) << msg;
    EXPECT_TRUE(Contains(msg, "malformed JSON"));
}

TEST_F(JsonFile, MalformedJsonAfterCommentsCountsCommentLines) {
    // The stray 'x' is on line 4, column 11.
    const std::string path = write("bad.json", "// header\n/* two\n   lines */\n{\"a\": 1,  x}\n");
    const std::string msg = config_error([&] { read_json_file(path); });
    EXPECT_TRUE(Contains(msg, path + ":4:11:")) << msg;
}

TEST_F(JsonFile, ErrorOnFirstCharacterIsLine1Column1) {
    const std::string path = write("bad.json", "x");
    EXPECT_TRUE(Contains(config_error([&] { read_json_file(path); }), path + ":1:1:"));
}

TEST_F(JsonFile, EmptyFileIsMalformed) {
    const std::string path = write("empty.json", "");
    const std::string msg = config_error([&] { read_json_file(path); });
    EXPECT_TRUE(Contains(msg, path + ":1:1:")) << msg;
    EXPECT_TRUE(Contains(msg, "malformed JSON"));
}

TEST_F(JsonFile, TruncatedFileNamesTheEnd) {
    // `{"name": "t"` is 12 characters: the end of input is column 13 of line 1.
    const std::string path = write("cut.json", "{\"name\": \"t\"");
    EXPECT_TRUE(Contains(config_error([&] { read_json_file(path); }), path + ":1:13:"));
}

TEST_F(JsonFile, TrailingGarbageIsMalformed) {
    const std::string path = write("tail.json", "{\"a\": 1}\n\n  junk\n");
    EXPECT_TRUE(Contains(config_error([&] { read_json_file(path); }), path + ":3:"));
}

TEST_F(JsonFile, MissingFileNamesThePath) {
    const std::string path = (dir_ / "nope.json").string();
    const std::string msg = config_error([&] { read_json_file(path); });
    EXPECT_TRUE(Contains(msg, path));
    EXPECT_TRUE(Contains(msg, "JSON file not found"));
}

// ---- JsonReader: typed access -----------------------------------------------------------

TEST(JsonReader, RootMustBeAnObject) {
    const json j = json::array({1, 2});
    const std::string msg = config_error([&] { JsonReader r(j, "cfg.json"); });
    EXPECT_TRUE(Contains(msg, "cfg.json"));
    EXPECT_TRUE(Contains(msg, "expected a JSON object"));
    EXPECT_TRUE(Contains(msg, "[1,2]"));
}

TEST(JsonReader, RequiredReadsEveryType) {
    const json j = {{"i", 7}, {"d", 2.5}, {"di", 3}, {"b", true}, {"s", "x"}, {"v", {1, 2, 3}}, {"big", 5000000000LL}};
    JsonReader r(j, "cfg.json");
    EXPECT_EQ(r.required<int>("i", "an integer"), 7);
    EXPECT_EQ(r.required<double>("d", "a number"), 2.5);
    EXPECT_EQ(r.required<double>("di", "a number"), 3.0);  // an integer is a number
    EXPECT_TRUE(r.required<bool>("b", "a flag"));
    EXPECT_EQ(r.required<std::string>("s", "a string"), "x");
    EXPECT_EQ(r.required<std::vector<int>>("v", "3 integers"), (std::vector<int>{1, 2, 3}));
    EXPECT_EQ(r.required<int64_t>("big", "a count"), 5000000000LL);
    EXPECT_NO_THROW(r.finish());
}

TEST(JsonReader, MissingRequiredKeyNamesTheKeyPathAndExpectation) {
    const json j = {{"sampler", json::object()}};
    JsonReader root(j, "cfg.json");
    JsonReader s = root.object("sampler");
    const std::string msg = config_error([&] { s.required<int>("threads", "a thread count"); });
    EXPECT_TRUE(Contains(msg, "cfg.json"));
    EXPECT_TRUE(Contains(msg, "'sampler.threads'"));
    EXPECT_TRUE(Contains(msg, "missing"));
    EXPECT_TRUE(Contains(msg, "a thread count"));
}

TEST(JsonReader, WrongTypeNamesKeyExpectationAndValueSeen) {
    const json j = {{"sampler", {{"threads", "2"}}}};
    JsonReader root(j, "cfg.json");
    JsonReader s = root.object("sampler");
    const std::string msg = config_error([&] { s.required<int>("threads", "a thread count"); });
    EXPECT_TRUE(Contains(msg, "cfg.json: key 'sampler.threads'"));
    EXPECT_TRUE(Contains(msg, "expected a thread count"));
    EXPECT_TRUE(Contains(msg, "\"2\""));
}

TEST(JsonReader, IntegerRejectsFloatBoolAndString) {
    const json j = {{"f", 2.5}, {"f0", 2.0}, {"b", true}, {"s", "3"}, {"n", nullptr}};
    JsonReader r(j, "cfg.json");
    for (const char* key : {"f", "f0", "b", "s", "n"}) {
        const std::string msg = config_error([&] { r.required<int>(key, "an integer"); });
        EXPECT_TRUE(Contains(msg, std::string("'") + key + "'")) << key;
        EXPECT_TRUE(Contains(msg, "expected an integer")) << key;
    }
}

TEST(JsonReader, OtherTypesRejectMismatches) {
    const json j = {{"i", 1}, {"s", "x"}, {"o", json::object()}};
    JsonReader r(j, "cfg.json");
    EXPECT_TRUE(Contains(config_error([&] { r.required<bool>("i", "true or false"); }), "expected true or false, got 1"));
    EXPECT_TRUE(Contains(config_error([&] { r.required<double>("s", "a number"); }), "expected a number, got \"x\""));
    EXPECT_TRUE(Contains(config_error([&] { r.required<std::string>("i", "a name"); }), "expected a name, got 1"));
    EXPECT_TRUE(Contains(config_error([&] { r.required<std::vector<double>>("s", "3 numbers"); }), "'s'"));
    EXPECT_TRUE(Contains(config_error([&] { r.required<std::vector<int>>("o", "3 integers"); }), "expected 3 integers"));
}

TEST(JsonReader, OptionalReturnsFallbackOnlyWhenAbsent) {
    const json j = {{"threads", 4}, {"bad", "x"}};
    JsonReader r(j, "cfg.json", "sampler");
    EXPECT_EQ(r.optional<int>("threads", 0, "a count"), 4);
    EXPECT_EQ(r.optional<int>("device", 3, "an ordinal"), 3);
    EXPECT_EQ(r.optional<std::string>("kernel", "k", "a name"), "k");
    const std::string msg = config_error([&] { r.optional<int>("bad", 0, "a count"); });
    EXPECT_TRUE(Contains(msg, "'sampler.bad'"));
    EXPECT_TRUE(Contains(msg, "expected a count"));
}

// A JSON integer beyond int's range must not wrap around silently ("threads": 5e9 became
// 705032704 threads in a run): it is rejected, quoting the value.
TEST(JsonReader, IntegerOutOfRangeIsRejected) {
    const json j = {{"threads", 5000000000LL}, {"neg", -5000000000LL}, {"huge", 18446744073709551615ULL},
                    {"fits", 2147483647}};
    JsonReader r(j, "cfg.json", "sampler");
    const std::string msg = config_error([&] { r.required<int>("threads", "a thread count"); });
    EXPECT_TRUE(Contains(msg, "'sampler.threads'"));
    EXPECT_TRUE(Contains(msg, "5000000000"));
    EXPECT_TRUE(Contains(msg, "out of range"));
    EXPECT_TRUE(Contains(config_error([&] { r.required<int>("neg", "a count"); }), "-5000000000"));
    EXPECT_TRUE(Contains(config_error([&] { r.required<int64_t>("huge", "a count"); }), "18446744073709551615"));
    EXPECT_EQ(r.required<int>("fits", "a count"), 2147483647);
    EXPECT_EQ(r.required<int64_t>("threads", "a count"), 5000000000LL);
    EXPECT_EQ(r.required<uint64_t>("huge", "a count"), 18446744073709551615ULL);
    EXPECT_TRUE(Contains(config_error([&] { r.required<uint32_t>("neg", "a count"); }), "out of range"));
}

// Elements of arrays are type-checked one by one: a fractional resolution entry is rejected,
// naming the entry, not truncated.
TEST(JsonReader, ArrayOfIntegersRejectsFractionalEntries) {
    const json j = {{"resolution", {80, 80.5, 80}}, {"big", {1, 5000000000LL}}, {"names", {"a", 3}}};
    JsonReader r(j, "cfg.json", "lattices[0]");
    const std::string msg = config_error([&] { r.required<std::vector<int>>("resolution", "an array of 3 integers"); });
    EXPECT_TRUE(Contains(msg, "'lattices[0].resolution'"));
    EXPECT_TRUE(Contains(msg, "[80,80.5,80]"));
    EXPECT_TRUE(Contains(msg, "entry 1, 80.5"));
    EXPECT_TRUE(Contains(config_error([&] { r.required<std::vector<int>>("big", "integers"); }), "out of range"));
    EXPECT_TRUE(Contains(config_error([&] { r.required<std::vector<std::string>>("names", "names"); }), "entry 1, 3"));
    EXPECT_EQ(r.required<std::vector<double>>("resolution", "numbers"), (std::vector<double>{80, 80.5, 80}));
}

// A misspelt required key: the message names the key present in the config and suggests
// the one that is missing.
TEST(JsonReader, MissingRequiredKeySuggestsAPresentTypo) {
    const json j = {{"name", "x"}, {"latices", json::array()}};
    JsonReader r(j, "cfg.json");
    r.required<std::string>("name", "a name");
    const std::string msg = config_error([&] { r.objects("lattices"); });
    EXPECT_TRUE(Contains(msg, "cfg.json: key 'lattices': missing"));
    EXPECT_TRUE(Contains(msg, "'latices'"));
    EXPECT_TRUE(Contains(msg, "did you mean 'lattices'?"));
    const std::string far = config_error([&] { r.required<int>("resolution", "a count"); });
    EXPECT_FALSE(Contains(far, "did you mean"));
}

// A reader with a resolved tree records what it reads, defaults included.
TEST(JsonReader, RecordsResolvedValuesAndDefaults) {
    const json j = {{"sampler", {{"threads", 2}}}, {"lattices", {{{"type", "cc"}}}}};
    auto resolved = std::make_shared<json>(j);
    JsonReader root(j, "cfg.json", "", resolved, json::json_pointer());
    JsonReader s = root.object("sampler");
    EXPECT_EQ(s.optional<int>("threads", 0, "a count"), 2);
    EXPECT_EQ(s.choice("precision", {"float", "double"}, "float"), "float");
    JsonReader d = root.optional_object("domain");
    EXPECT_EQ(d.optional<double>("margin", 0.1, "a fraction"), 0.1);
    EXPECT_EQ(d.path(), "domain");
    std::vector<JsonReader> ls = root.objects("lattices");
    EXPECT_EQ(ls[0].choice("type", {"cc", "bcc"}, "cc"), "cc");
    EXPECT_EQ(ls[0].optional<int>("n", 7, "n"), 7);
    EXPECT_EQ(*resolved, (json{{"sampler", {{"threads", 2}, {"precision", "float"}}},
                               {"domain", {{"margin", 0.1}}},
                               {"lattices", {{{"type", "cc"}, {"n", 7}}}}}));
}

// ---- objects, choice --------------------------------------------------------------------

TEST(JsonReader, ObjectsNameTheArrayIndexInKeyPaths) {
    const json j = {{"lattices", {{{"resolution", {8, 8, 8}}}, {{"resolution", "big"}}}}};
    JsonReader root(j, "cfg.json");
    std::vector<JsonReader> ls = root.objects("lattices");
    ASSERT_EQ(ls.size(), 2u);
    EXPECT_EQ(ls[0].path(), "lattices[0]");
    EXPECT_EQ(ls[1].key_path("resolution"), "lattices[1].resolution");
    EXPECT_EQ(ls[0].required<std::vector<int>>("resolution", "3 integers"), (std::vector<int>{8, 8, 8}));
    const std::string msg = config_error([&] { ls[1].required<std::vector<int>>("resolution", "an array of 3 integers"); });
    EXPECT_TRUE(Contains(msg, "cfg.json: key 'lattices[1].resolution'"));
    EXPECT_TRUE(Contains(msg, "expected an array of 3 integers"));
    EXPECT_TRUE(Contains(msg, "\"big\""));
}

TEST(JsonReader, ObjectsRejectNonArraysAndNonObjectElements) {
    const json j = {{"a", {{"x", 1}}}, {"b", {json::object(), 5}}};
    JsonReader root(j, "cfg.json");
    const std::string not_array = config_error([&] { root.objects("a"); });
    EXPECT_TRUE(Contains(not_array, "'a'"));
    EXPECT_TRUE(Contains(not_array, "expected an array of objects"));
    const std::string bad_element = config_error([&] { root.objects("b"); });
    EXPECT_TRUE(Contains(bad_element, "'b[1]'"));
    EXPECT_TRUE(Contains(bad_element, "expected an object, got 5"));
    EXPECT_TRUE(Contains(config_error([&] { root.objects("missing"); }), "'missing': missing"));
}

TEST(JsonReader, ObjectRejectsNonObjectsAndNestsPaths) {
    const json j = {{"sampler", 3}, {"output", {{"inner", {{"k", 1}}}}}};
    JsonReader root(j, "cfg.json");
    const std::string msg = config_error([&] { root.object("sampler"); });
    EXPECT_TRUE(Contains(msg, "'sampler'"));
    EXPECT_TRUE(Contains(msg, "expected a JSON object, got 3"));
    JsonReader out = root.object("output");
    JsonReader inner = out.object("inner");
    EXPECT_EQ(inner.path(), "output.inner");
    EXPECT_TRUE(Contains(config_error([&] { inner.required<std::string>("k", "a name"); }), "'output.inner.k'"));
}

TEST(JsonReader, ChoiceAcceptsListedValuesAndFallsBack) {
    const json j = {{"precision", "double"}};
    JsonReader r(j, "cfg.json", "sampler");
    EXPECT_EQ(r.choice("precision", {"float", "double"}, "float"), "double");
    EXPECT_EQ(r.choice("backend", {"cpu", "cuda"}, "cpu"), "cpu");
}

TEST(JsonReader, ChoiceRejectsUnknownValueWithSuggestion) {
    const json j = {{"precision", "doubel"}, {"strategy", "zzzzzzzzzzzz"}, {"n", 3}};
    JsonReader r(j, "cfg.json", "sampler");
    const std::string msg = config_error([&] { r.choice("precision", {"float", "double"}, "float"); });
    EXPECT_TRUE(Contains(msg, "cfg.json: key 'sampler.precision'"));
    EXPECT_TRUE(Contains(msg, "\"doubel\""));
    EXPECT_TRUE(Contains(msg, "\"float\" or \"double\""));
    EXPECT_TRUE(Contains(msg, "did you mean \"double\""));
    const std::string far = config_error([&] { r.choice("strategy", {"two_grids", "double_resolution"}, "two_grids"); });
    EXPECT_TRUE(Contains(far, "expected one of \"two_grids\" or \"double_resolution\""));
    EXPECT_FALSE(Contains(far, "did you mean"));
    const std::string not_string = config_error([&] { r.choice("n", {"a", "b"}, "a"); });
    EXPECT_TRUE(Contains(not_string, "'sampler.n'"));
    EXPECT_TRUE(Contains(not_string, "one of \"a\" or \"b\""));
}

// ---- finish -----------------------------------------------------------------------------

TEST(JsonReader, FinishRejectsUnknownKeyWithNearestSuggestion) {
    const json j = {{"name", "x"}, {"latices", json::array()}, {"lattices2", 1}};
    JsonReader r(j, "cfg.json");
    r.required<std::string>("name", "a name");
    r.optional<int>("lattices", 0, "ignored");  // asked about but absent: still a valid key
    const std::string msg = config_error([&] { r.finish(); });
    EXPECT_TRUE(Contains(msg, "cfg.json: unknown key '"));
    EXPECT_TRUE(Contains(msg, "did you mean 'lattices'?"));
    EXPECT_TRUE(Contains(msg, "valid here: name, lattices"));
}

TEST(JsonReader, FinishSuggestsOptionalKeysAskedAboutButAbsent) {
    const json j = {{"sampler", {{"threds", 2}}}};
    JsonReader root(j, "cfg.json");
    JsonReader s = root.object("sampler");
    EXPECT_EQ(s.optional<int>("threads", 0, "a count"), 0);
    EXPECT_FALSE(s.has("precision"));
    const std::string msg = config_error([&] { s.finish(); });
    EXPECT_TRUE(Contains(msg, "unknown key 'sampler.threds'"));
    EXPECT_TRUE(Contains(msg, "did you mean 'threads'?"));
    EXPECT_TRUE(Contains(msg, "precision"));
}

TEST(JsonReader, FinishWithoutCloseKeyGivesNoSuggestion) {
    const json j = {{"name", "x"}, {"zzzzzzzzzz", 1}};
    JsonReader r(j, "cfg.json");
    r.required<std::string>("name", "a name");
    const std::string msg = config_error([&] { r.finish(); });
    EXPECT_TRUE(Contains(msg, "unknown key 'zzzzzzzzzz'"));
    EXPECT_FALSE(Contains(msg, "did you mean"));
}

TEST(JsonReader, FinishAcceptsAskedAndAlsoAllowedKeys) {
    const json j = {{"name", "x"}, {"notation", "8x8x8"}, {"points", 512}};
    JsonReader r(j, "cfg.json", "lattice");
    r.required<std::string>("name", "a name");
    EXPECT_NO_THROW(r.finish({"notation", "points"}));
    JsonReader strict(j, "cfg.json", "lattice");
    strict.required<std::string>("name", "a name");
    const std::string msg = config_error([&] { strict.finish({"points"}); });
    EXPECT_TRUE(Contains(msg, "unknown key 'lattice.notation'"));
}

TEST(JsonReader, FailAndKeyPath) {
    const json j = json::object();
    JsonReader top(j, "cfg.json");
    JsonReader nested(j, "cfg.json", "domain");
    EXPECT_EQ(top.key_path("margin"), "margin");
    EXPECT_EQ(nested.key_path("margin"), "domain.margin");
    EXPECT_EQ(config_error([&] { nested.fail("margin", "expected a non-negative fraction"); }),
              "cfg.json: key 'domain.margin': expected a non-negative fraction");
    EXPECT_EQ(top.file(), "cfg.json");
}

// ---- edit distance and suggestions --------------------------------------------------------

TEST(EditDistance, TextbookValues) {
    EXPECT_EQ(edit_distance("", ""), 0);
    EXPECT_EQ(edit_distance("abc", "abc"), 0);
    EXPECT_EQ(edit_distance("", "abc"), 3);
    EXPECT_EQ(edit_distance("abc", ""), 3);
    EXPECT_EQ(edit_distance("kitten", "sitting"), 3);
    EXPECT_EQ(edit_distance("flaw", "lawn"), 2);
    EXPECT_EQ(edit_distance("latices", "lattices"), 1);  // one insertion
    EXPECT_EQ(edit_distance("thread", "threads"), 1);
    EXPECT_EQ(edit_distance("ab", "ba"), 2);              // a transposition is two edits
    EXPECT_EQ(edit_distance("intention", "execution"), 5);
}

TEST(EditDistance, IsSymmetric) {
    const std::vector<std::string> words = {"", "a", "mesh", "lattices", "latices", "sampler", "smapler", "bcc"};
    for (const auto& a : words)
        for (const auto& b : words) EXPECT_EQ(edit_distance(a, b), edit_distance(b, a)) << a << " / " << b;
}

TEST(NearestMatch, FindsLikelyTyposOnly) {
    const std::vector<std::string> keys = {"name", "mesh", "lattices", "sampler", "domain"};
    EXPECT_EQ(nearest_match("latices", keys), "lattices");
    EXPECT_EQ(nearest_match("smapler", keys), "sampler");
    EXPECT_EQ(nearest_match("Mesh", keys), "mesh");
    EXPECT_EQ(nearest_match("sampler", keys), "sampler");
    EXPECT_EQ(nearest_match("completely_unrelated", keys), "");
    EXPECT_EQ(nearest_match("anything", {}), "");
}

}  // namespace
}  // namespace sdf
