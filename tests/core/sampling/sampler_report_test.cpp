// The typed provenance of a field (core/sampling/sampler_report.h, core/mesh/mesh_provenance.h):
// merge sums the counters of the parts of one lattice, whatever the order and however it is
// cut; the JSON is the keys field headers and manifests have always had, read back to the
// same record; a wrong type names its key.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

#include "core/mesh/mesh_provenance.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/sampling/sampler_report.h"

namespace sdf {
namespace {

/// The report a sampler gives one part: `points` computed, `in` of them in the band.
SamplerReport part(int64_t points, int64_t in, int64_t reranked, bool skips) {
    SamplerReport r;
    r.backend = "cpu";
    r.method = "bvh";
    r.kernel = "brick";
    r.precision = "float";
    r.points_computed = points;
    r.details["threads"] = 2;
    r.details["sign"] = {{"requested", "auto"}, {"mode", "pseudonormal"}, {"reason", "closed"}};
    BandReport b;
    b.width = 0.125;
    b.points_in_band = in;
    b.points_outside = points - in;
    b.how = skips ? "bricks skipped by the distance bound" : "post-processed";
    b.counts_skips = skips;
    b.probes = skips ? points / 8 : 0;
    b.bricks_skipped = skips ? 3 : 0;
    b.points_skipped = skips ? 5 : 0;
    r.band = b;
    CertificateReport c;
    c.counted = true;
    c.points = points;
    c.reranked_in_double = reranked;
    c.full_double_search = reranked / 2;
    r.search_certificate = c;
    return r;
}

TEST(SamplerReport, MergeSumsEveryCounterAndKeepsTheFirstPartsDetails) {
    SamplerReport whole;
    whole.merge(part(100, 40, 10, true));
    whole.merge(SamplerReport());  // an empty slab (a rank with no planes) adds nothing
    whole.merge(part(50, 20, 4, true));
    whole.merge(part(30, 1, 0, true));
    EXPECT_EQ(whole.points_computed, 180);
    ASSERT_TRUE(whole.band && whole.search_certificate);
    EXPECT_EQ(whole.band->points_in_band, 61);
    EXPECT_EQ(whole.band->points_outside, 119);
    EXPECT_EQ(whole.band->probes, 100 / 8 + 50 / 8 + 30 / 8);
    EXPECT_EQ(whole.band->bricks_skipped, 9);
    EXPECT_EQ(whole.band->points_skipped, 15);
    EXPECT_EQ(whole.band->width, 0.125);
    EXPECT_EQ(whole.search_certificate->points, 180);
    EXPECT_EQ(whole.search_certificate->reranked_in_double, 14);
    EXPECT_EQ(whole.search_certificate->full_double_search, 5 + 2 + 0);
    EXPECT_EQ(whole.details.at("threads"), 2);
    EXPECT_EQ(whole.kernel, "brick");

    SamplerReport reversed;  // the order of the parts does not matter to the counters
    reversed.merge(part(30, 1, 0, true));
    reversed.merge(part(50, 20, 4, true));
    reversed.merge(part(100, 40, 10, true));
    EXPECT_EQ(nlohmann::json(reversed), nlohmann::json(whole));
}

TEST(SamplerReport, JsonHasTheRecordedKeysAndReadsBackToTheSameRecord) {
    const SamplerReport r = part(100, 40, 10, true);
    const nlohmann::json j = r;
    EXPECT_EQ(j.at("backend"), "cpu");
    EXPECT_EQ(j.at("points_computed"), 100);
    EXPECT_EQ(j.at("threads"), 2);
    EXPECT_EQ(j.at("sign").at("mode"), "pseudonormal");
    EXPECT_EQ(j.at("band"), (nlohmann::json{{"width", 0.125}, {"points_in_band", 40}, {"points_outside", 60},
                                             {"how", "bricks skipped by the distance bound"}, {"probes", 12},
                                             {"bricks_skipped", 3}, {"points_skipped", 5}}));
    EXPECT_EQ(j.at("search_certificate"),
              (nlohmann::json{{"certified", true}, {"points", 100}, {"reranked_in_double", 10}, {"full_double_search", 5},
                              {"reranked_fraction", 0.1}}));
    EXPECT_EQ(nlohmann::json(j.get<SamplerReport>()), j);

    const SamplerReport post = part(10, 4, 0, false);  // no skip counters: none written
    EXPECT_FALSE(nlohmann::json(post).at("band").contains("probes"));
    EXPECT_EQ(nlohmann::json(nlohmann::json(post).get<SamplerReport>()), nlohmann::json(post));

    SamplerReport arrays;  // a field made from arrays: its details only
    arrays.details["source"] = "arrays";
    EXPECT_EQ(nlohmann::json(arrays), (nlohmann::json{{"source", "arrays"}}));
    EXPECT_TRUE(nlohmann::json(SamplerReport()).is_null());
    EXPECT_TRUE(nlohmann::json(nullptr).get<SamplerReport>().empty());
}

TEST(SamplerReport, AWrongTypeNamesItsKey) {
    nlohmann::json j = part(100, 40, 10, true);
    j["band"]["points_in_band"] = "forty";
    try {
        (void)j.get<SamplerReport>();
        FAIL() << "accepted a string count";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("sampler.band.points_in_band: expected an integer"), std::string::npos) << e.what();
    }
    EXPECT_THROW((void)nlohmann::json::array().get<SamplerReport>(), std::runtime_error);
}

TEST(MeshProvenance, OneRecordReadBackWholeAndTheEarlierShortOneIntoItsReport) {
    const PreparedMesh mesh = prepare_mesh(make_torus(1.0, 0.35, 12, 8));
    const MeshProvenance m = describe_prepared_mesh(mesh);
    const nlohmann::json j = m;
    for (const char* key : {"name", "source", "sha256", "vertices", "triangles", "bounds", "report"}) EXPECT_TRUE(j.contains(key)) << key;
    EXPECT_EQ(j.at("triangles"), int64_t(mesh.triangles().size()));
    EXPECT_EQ(j.at("report").at("components"), 1);
    EXPECT_TRUE(j.at("report").contains("sign_reliable"));
    EXPECT_EQ(nlohmann::json(j.get<MeshProvenance>()), j);

    const nlohmann::json short_record = {{"name", "torus"}, {"source", "shape:torus"}, {"sha256", "ab"}, {"vertices", 96},
                                         {"triangles", 192}, {"components", 1}, {"sign_reliable", true}};
    const nlohmann::json read = nlohmann::json(short_record.get<MeshProvenance>());
    EXPECT_FALSE(read.contains("bounds"));
    EXPECT_EQ(read.at("report"), (nlohmann::json{{"components", 1}, {"sign_reliable", true}}));
    EXPECT_EQ(nlohmann::json(MeshProvenance()), nlohmann::json::object());
    EXPECT_THROW((void)nlohmann::json({{"name", "x"}, {"vertices", "many"}}).get<MeshProvenance>(), std::runtime_error);
}

/// One stage counter of the winding sign (`key`, the member `count`) over two parts of 100 and
/// 50 points: summed over slabs and ranks like the others, written, read back, a field
/// written before the stage (no key) read as 0, a negative count that the total still adds up
/// to refused naming the key, and a total without the stage refused.
void expect_stage_counter(const std::string& key, int64_t WindingSignReport::*count, const WindingSignReport& a_counts,
                          const WindingSignReport& b_counts) {
    SamplerReport a = part(100, 40, 10, true), b = part(50, 20, 4, true);
    a.winding_sign = a_counts;
    b.winding_sign = b_counts;
    SamplerReport whole;
    whole.merge(a);
    whole.merge(b);
    ASSERT_TRUE(whole.winding_sign.has_value());
    const int64_t sum = a_counts.*count + b_counts.*count;
    EXPECT_EQ((*whole.winding_sign).*count, sum) << key;
    EXPECT_EQ(whole.winding_sign->points(), 150) << key;
    const nlohmann::json j = whole;
    EXPECT_EQ(j.at("winding_sign").at(key), sum) << key;
    EXPECT_EQ((*j.get<SamplerReport>().winding_sign).*count, sum) << key;
    nlohmann::json before = j;
    before["winding_sign"].erase(key);
    before["winding_sign"]["points"] = 150 - sum;
    EXPECT_EQ((*before.get<SamplerReport>().winding_sign).*count, 0) << key;
    nlohmann::json wrong = j;
    wrong["winding_sign"]["points"] = 150 - sum;  // the total without the stage
    EXPECT_THROW((void)wrong.get<SamplerReport>(), std::runtime_error) << key;
    nlohmann::json negative = j;
    negative["winding_sign"][key] = -3;
    negative["winding_sign"]["points"] = 150 - sum - 3;
    try {
        (void)negative.get<SamplerReport>();
        ADD_FAILURE() << "a negative count was read: " << key;
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("sampler.winding_sign." + key + ": expected a count >= 0"), std::string::npos)
            << e.what();
    }
}

/// The surface stage's counter (the walk, kernels/winding/surface_side.h) and the nearest
/// triangles' (nearest_side), each absent in fields written before it.
TEST(SamplerReport, WindingSurfaceAndNearestCountersMergeAndReadBack) {
    expect_stage_counter("surface", &WindingSignReport::surface, WindingSignReport{2, 1, 0, 0, 97}, WindingSignReport{0, 0, 0, 1, 49});
    expect_stage_counter("nearest", &WindingSignReport::nearest, WindingSignReport{2, 1, 0, 0, 17, 80},
                         WindingSignReport{0, 0, 0, 1, 9, 40});
    // Counts whose sum would overflow (points() adds them) are refused before it is taken.
    SamplerReport r = part(100, 40, 10, true);
    r.winding_sign = WindingSignReport{0, 0, 0, 0, 1, 99};
    nlohmann::json huge = r;
    huge["winding_sign"]["nearest"] = std::numeric_limits<int64_t>::max();
    try {
        (void)huge.get<SamplerReport>();
        ADD_FAILURE() << "counts that overflow were read";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("sum fits in 64 bits"), std::string::npos) << e.what();
    }
}

/// The certified winding sign's counters (kernels/winding/certified_winding.h): summed by
/// merge, written with their total, read back, and a total that does not add up is refused.
TEST(SamplerReport, WindingSignCountersMergeAndRoundTrip) {
    SamplerReport a = part(100, 40, 10, true), b = part(50, 20, 4, true);
    a.winding_sign = WindingSignReport{90, 8, 1, 1, 0};
    b.winding_sign = WindingSignReport{45, 5, 0, 0, 0};
    SamplerReport whole;
    whole.merge(a);
    whole.merge(SamplerReport());
    whole.merge(b);
    ASSERT_TRUE(whole.winding_sign.has_value());
    EXPECT_EQ(whole.winding_sign->fast, 135);
    EXPECT_EQ(whole.winding_sign->refined, 13);
    EXPECT_EQ(whole.winding_sign->direct, 1);
    EXPECT_EQ(whole.winding_sign->ties, 1);
    EXPECT_EQ(whole.winding_sign->surface, 0);
    const nlohmann::json j = whole;
    EXPECT_EQ(j.at("winding_sign").at("points"), 150);
    const SamplerReport back = j.get<SamplerReport>();
    ASSERT_TRUE(back.winding_sign.has_value());
    EXPECT_EQ(back.winding_sign->points(), 150);
    EXPECT_EQ(back.winding_sign->ties, 1);
    EXPECT_FALSE(back.details.contains("winding_sign"));
    nlohmann::json bad = j;
    bad["winding_sign"]["points"] = 151;
    try {
        (void)bad.get<SamplerReport>();
        FAIL() << "a total that does not add up was read";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("sampler.winding_sign.points"), std::string::npos) << e.what();
    }
    bad = j;
    bad["winding_sign"]["fast"] = "many";
    EXPECT_THROW((void)bad.get<SamplerReport>(), std::runtime_error);
}

}  // namespace
}  // namespace sdf
