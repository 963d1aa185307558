// The "render" config block: defaults, named and explicit views, and errors that name the
// key, the value and what was expected.
#include <gtest/gtest.h>

#include "harness/config/render_spec.h"
#include "harness/render/thesis_figure.h"

namespace sdf {
namespace {

RenderSpec parse(const std::string& text) {
    static nlohmann::json keep;  // the reader refers to the JSON while parsing
    keep = nlohmann::json::parse(text);
    JsonReader r(keep, "test.json", "render");
    return parse_render_spec(r);
}

std::string error_of(const std::string& text) {
    try {
        parse(text);
    } catch (const ConfigError& e) {
        return e.what();
    }
    return "(accepted)";
}

TEST(RenderSpec, Defaults) {
    const RenderSpec s = parse("{}");
    EXPECT_EQ(s.width, 512);
    EXPECT_EQ(s.height, 512);
    ASSERT_EQ(s.views.size(), 1u);
    EXPECT_EQ(s.views[0].name, "three_quarter");
    EXPECT_TRUE(s.reference);
    EXPECT_EQ(s.backend, "auto");
}

TEST(RenderSpec, NamedExplicitAndAdjustedViews) {
    const RenderSpec s = parse(R"({"size": [640, 480], "fov": 25, "views": ["dragon_side", "dragon_front",
        {"name": "close", "eye": [0, 0.2, 0.4], "target": [0, 0.12, 0], "fov": 20},
        {"view": "top", "margin": 0.1, "name": "top_wide"}], "backend": "cpu", "grid_downsample": 2})");
    EXPECT_EQ(s.width, 640);
    EXPECT_EQ(s.height, 480);
    ASSERT_EQ(s.views.size(), 4u);
    EXPECT_EQ(s.views[0].name, "dragon_side");
    EXPECT_EQ(s.views[0].fov_y_degrees, 25);
    EXPECT_TRUE(s.views[2].explicit_camera);
    EXPECT_EQ(s.views[2].eye, Vec3d(0, 0.2, 0.4));
    EXPECT_EQ(s.views[2].up, Vec3d(0, 1, 0));
    EXPECT_EQ(s.views[2].fov_y_degrees, 20);
    EXPECT_FALSE(s.views[3].explicit_camera);
    EXPECT_EQ(s.views[3].name, "top_wide");
    EXPECT_EQ(s.views[3].margin, 0.1);
    EXPECT_EQ(s.grid_downsample, 2);
    EXPECT_EQ(parse(R"({"size": 256})").height, 256);
}

TEST(RenderSpec, BecomesFigureOptions) {
    const FigureOptions o = figure_options(parse(
        R"({"backend": "cpu", "precision": "double", "error_maps": false, "heat_max_degrees": 5, "grid_downsample": 3})"));
    EXPECT_EQ(o.render.backend, "cpu");
    EXPECT_EQ(o.render.precision, Precision::Double);
    EXPECT_TRUE(o.reference_row);
    EXPECT_FALSE(o.error_rows);
    EXPECT_EQ(o.heat_max_degrees, 5);
    EXPECT_EQ(o.downsample, 3);
    EXPECT_FALSE(figure_options(parse(R"({"reference": false})")).error_rows);  // heat maps need the reference
}

TEST(RenderSpec, ErrorsNameKeyValueAndExpectation) {
    EXPECT_NE(error_of(R"({"views": ["sidee"]})").find("unknown view \"sidee\""), std::string::npos);
    EXPECT_NE(error_of(R"({"views": ["sidee"]})").find("render.views[0]"), std::string::npos);
    EXPECT_NE(error_of(R"({"size": [0, 5]})").find("render.size"), std::string::npos);
    EXPECT_NE(error_of(R"({"fov": 200})").find("(0, 180)"), std::string::npos);
    EXPECT_NE(error_of(R"({"views": [{"name": "x", "eye": [0, 0, 1]}]})").find("target"), std::string::npos);
    EXPECT_NE(error_of(R"({"views": [{"name": "x", "eye": [0, 0, 1], "target": [0, 0, 0], "up": [0, 0, 2]}]})")
                  .find("parallel"), std::string::npos);
    EXPECT_NE(error_of(R"({"views": [{"name": "x", "eye": [0, 0, 1], "target": [0, 0, 0], "fov": 30, "zoom": 2}]})")
                  .find("zoom"), std::string::npos);
    EXPECT_NE(error_of(R"({"backend": "gpu"})").find("backend"), std::string::npos);
    EXPECT_NE(error_of(R"({"sise": 5})").find("sise"), std::string::npos);
    EXPECT_NE(error_of(R"({"views": []})").find("non-empty"), std::string::npos);
}

TEST(RenderSpec, PanelsChooseAnyReconstructionOfTheTable) {
    EXPECT_TRUE(parse("{}").panels.empty());  // the thesis's five
    const RenderSpec s = parse(R"({"panels": ["bcc_cubic/true", "bcc_box_quintic", "cc_bspline3", "tricubic_lm"]})");
    ASSERT_EQ(s.panels.size(), 4u);
    EXPECT_EQ(s.panels[1].interpolator, "bcc_box_quintic");
    EXPECT_EQ(s.panels[1].derivatives, "fd");    // values only: its one source
    EXPECT_EQ(s.panels[3].derivatives, "true");  // reads derivatives: the field's gradients
    const FigureOptions o = figure_options(s);
    ASSERT_EQ(o.panels.size(), 4u);
    EXPECT_EQ(o.panels[0].letter, "A");
    EXPECT_EQ(o.panels[0].caption, "BCC cubic, true derivatives");
    EXPECT_EQ(o.panels[1].letter, "B");
    EXPECT_EQ(o.panels[1].lattice, LatticeType::BCC);
    EXPECT_EQ(o.panels[1].caption, "BCC quintic box spline, interpolating");
    EXPECT_EQ(o.panels[2].lattice, LatticeType::CC);
    EXPECT_EQ(o.panels[2].caption, "CC cubic B-spline, prefiltered");
    EXPECT_EQ(o.panels[3].caption, "CC tricubic, true derivatives");
    // Every filter of the table has a caption of its own (not the name fallback).
    for (const std::string& name : interpolator_names()) {
        const std::string source = derivative_source_name(default_derivative_source(parse_interpolator(name), true));
        EXPECT_NE(panel_caption(name, source), name + "/" + source) << name;
    }
}

TEST(RenderSpec, PanelErrorsNameTheEntry) {
    const std::string unknown = error_of(R"({"panels": ["bcc_cubic", "bcc_quintic"]})");
    EXPECT_NE(unknown.find("render.panels[1]"), std::string::npos) << unknown;
    EXPECT_NE(unknown.find("unknown interpolator 'bcc_quintic'"), std::string::npos) << unknown;
    EXPECT_NE(error_of(R"({"panels": ["bcc_box_quintic/true"]})").find("does not accept derivatives 'true'"), std::string::npos);
    EXPECT_NE(error_of(R"({"panels": []})").find("1 to 26"), std::string::npos);
    EXPECT_NE(error_of(R"({"panels": [3]})").find("render.panels[0]"), std::string::npos);
    const std::string twice = error_of(R"({"panels": ["catmull_rom", "bcc_linear", "catmull_rom/fd"]})");
    EXPECT_NE(twice.find("\"catmull_rom/fd\" is already panel A"), std::string::npos) << twice;
}

/// Two specs ask for the same render: every field, each view's camera as it resolves.
void expect_same(const RenderSpec& a, const RenderSpec& b) {
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.reference, b.reference);
    EXPECT_EQ(a.error_maps, b.error_maps);
    EXPECT_EQ(a.heat_max_degrees, b.heat_max_degrees);
    EXPECT_EQ(a.backend, b.backend);
    EXPECT_EQ(a.precision, b.precision);
    EXPECT_EQ(a.grid_downsample, b.grid_downsample);
    ASSERT_EQ(a.panels.size(), b.panels.size());
    for (size_t i = 0; i < a.panels.size(); ++i) {
        EXPECT_EQ(a.panels[i].interpolator, b.panels[i].interpolator);
        EXPECT_EQ(a.panels[i].derivatives, b.panels[i].derivatives);
    }
    ASSERT_EQ(a.views.size(), b.views.size());
    const Bounds3 box{{-1, -0.5, -2}, {1, 0.5, 2}};
    for (size_t i = 0; i < a.views.size(); ++i) {
        EXPECT_EQ(a.views[i].name, b.views[i].name);
        const CameraSpec ca = resolve_view(a.views[i], box, a.width, a.height);
        const CameraSpec cb = resolve_view(b.views[i], box, b.width, b.height);
        EXPECT_EQ(ca.name, cb.name);
        EXPECT_EQ(ca.eye, cb.eye);
        EXPECT_EQ(ca.target, cb.target);
        EXPECT_EQ(ca.up, cb.up);
        EXPECT_EQ(ca.fov_y_degrees, cb.fov_y_degrees);
    }
}

TEST(RenderSpec, ToJsonReadsBackToTheSameSpec) {
    for (const char* text :
         {"{}", R"({"size": [640, 480], "fov": 25, "margin": 0.2, "views": ["dragon_side",
              {"name": "close", "eye": [0, 0.2, 0.4], "target": [0, 0.12, 0], "up": [0, 0, 1], "fov": 20},
              {"view": "top", "margin": 0.1, "name": "top_wide"}], "reference": false, "error_maps": false,
              "heat_max_degrees": 7, "backend": "cpu", "precision": "double", "grid_downsample": 2,
              "panels": ["bcc_cubic", "catmull_rom/fd"]})"}) {
        const RenderSpec s = parse(text);
        const nlohmann::json j = render_spec_to_json(s);
        expect_same(s, render_spec_from_json(j, "round trip"));
        EXPECT_EQ(render_spec_to_json(render_spec_from_json(j, "round trip")), j) << text;
    }
    EXPECT_NE(render_spec_to_json(parse("{}")).dump().find(R"("views":[{"fov":30.0,"margin":0.04,"view":"three_quarter"}])"),
              std::string::npos);
}

TEST(RenderSpec, RenamedNamedViewFitsItsTableView) {
    // {"view": "top", "name": "top_wide"} fits the table's "top" and keeps the new name.
    const RenderSpec s = parse(R"({"views": [{"view": "top", "name": "top_wide"}, "top"]})");
    const Bounds3 box{{-1, -0.5, -2}, {1, 0.5, 2}};
    const CameraSpec renamed = resolve_view(s.views[0], box, 64, 64), plain = resolve_view(s.views[1], box, 64, 64);
    EXPECT_EQ(renamed.name, "top_wide");
    EXPECT_EQ(renamed.eye, plain.eye);
    EXPECT_EQ(renamed.up, plain.up);
}

TEST(RenderSpec, OptionsOfTheRayCaster) {
    const RenderOptions o = render_options(parse(R"({"backend": "cpu", "precision": "double"})"));
    EXPECT_EQ(o.backend, "cpu");
    EXPECT_EQ(o.precision, Precision::Double);
    EXPECT_EQ(render_options(parse("{}")).backend, "auto");
    EXPECT_EQ(render_options(parse("{}")).precision, Precision::Float);
}

}  // namespace
}  // namespace sdf
