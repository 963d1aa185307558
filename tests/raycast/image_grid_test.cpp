// Grids and image files: the layout's size and centring, labels drawn in their bands (with
// OpenImageIO), PNG/EXR round trips with the provenance attributes, PPM/PFM, no silent
// overwrite, and the thesis figure's panels, rows and metrics on a small pawn.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "harness/render/heat_map.h"
#include "harness/render/image_io.h"
#include "harness/render/label_font.h"
#include "harness/render/netpbm.h"
#include "harness/render/thesis_figure.h"
#include "tests/test_util/scratch_dir.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

namespace fs = std::filesystem;

ImageRgb solid(int w, int h, float r, float g, float b) {
    ImageRgb im(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) im.set(x, y, r, g, b);
    return im;
}

std::vector<GridRow> thesis_shaped_rows() {
    const ImageRgb img = solid(40, 30, 0.5f, 0.2f, 0.1f);
    return {{{img, "A"}, {img, "B  label"}, {img, "C"}}, {{img, "D"}, {img, "E"}}};
}

/// Pixels of `im` in the rectangle that differ from the grey level `bg`.
int non_background(const ImageRgb& im, int x0, int y0, int w, int h, float bg) {
    int n = 0;
    for (int y = y0; y < y0 + h; ++y)
        for (int x = x0; x < x0 + w; ++x) {
            const float* p = im.at(x, y);
            n += (std::abs(p[0] - bg) > 0.05f || std::abs(p[1] - bg) > 0.05f || std::abs(p[2] - bg) > 0.05f);
        }
    return n;
}

TEST(ImageGrid, LayoutSizeAndCentredRows) {
    GridStyle style;  // padding 12, font 20 -> label band 32, no title
    const GridLayout g = layout_grid(thesis_shaped_rows(), style);
    EXPECT_EQ(g.width, 3 * 40 + 4 * 12);
    EXPECT_EQ(g.height, 12 + 2 * (30 + 32 + 12));
    ASSERT_EQ(g.cells.size(), 2u);
    EXPECT_EQ(g.cells[0][0].x, 12);
    EXPECT_EQ(g.cells[1][0].x, (g.width - (2 * 40 + 3 * 12)) / 2 + 12);  // row 2 centred
    EXPECT_EQ(g.cells[1][0].y, 12 + 30 + 32 + 12);
    EXPECT_EQ(g.cells[0][1].label_y, 12 + 30);
    style.title = "a title";
    EXPECT_EQ(layout_grid(thesis_shaped_rows(), style).height, g.height + (26 * 8 + 4) / 5);
}

TEST(ImageGrid, ImagesAndLabelsAreDrawn) {
    const GridStyle style;
    const std::vector<GridRow> rows = thesis_shaped_rows();
    const ImageRgb grid = make_image_grid(rows, style);
    const GridLayout g = layout_grid(rows, style);
    ASSERT_EQ(grid.width, g.width);
    ASSERT_EQ(grid.height, g.height);
    // Every image is where the layout says
    for (const auto& row : g.cells)
        for (const GridCellPlacement& p : row) EXPECT_NEAR(grid.at(p.x + 5, p.y + 5)[1], 0.2f, 1e-6f);
    if (!have_openimageio()) GTEST_SKIP() << "built without OpenImageIO: labels are not drawn";
    for (const auto& row : g.cells)
        for (const GridCellPlacement& p : row)
            EXPECT_GT(non_background(grid, p.label_x, p.label_y, p.label_width, p.label_height, style.background), 10);
    // The longer label covers more pixels than a one-letter one
    const GridCellPlacement& a = g.cells[0][0];
    const GridCellPlacement& b = g.cells[0][1];
    EXPECT_GT(non_background(grid, b.label_x, b.label_y, b.label_width, b.label_height, 1.0f),
              non_background(grid, a.label_x, a.label_y, a.label_width, a.label_height, 1.0f));
}

TEST(ImageGrid, LabelFontIsFoundOrOverridden) {
    if (!have_openimageio()) GTEST_SKIP() << "labels need OpenImageIO";
    const std::string font = find_label_font();
    EXPECT_TRUE(fs::is_regular_file(font)) << font;
    setenv("SDF_FONT", font.c_str(), 1);
    EXPECT_EQ(find_label_font(), font);
    unsetenv("SDF_FONT");
}

TEST(ImageFiles, PngAndExrRoundTripWithProvenance) {
    const test::ScratchDir dir("sdf_grid_test");
    const ImageRgb im = solid(7, 5, 0.25f, 0.5f, 1.0f);
    const nlohmann::json attributes = {{"config_hash", "abc123"}, {"git_commit", "deadbeef"}, {"render_seconds", 0.5}};
    if (!have_openimageio()) {
        EXPECT_EQ(write_image(dir.at("a.png"), im, attributes), dir.at("a.ppm"));
        EXPECT_TRUE(fs::exists(dir.at("a.ppm.json")));
        GTEST_SKIP() << "built without OpenImageIO: PNG/EXR fall back to PPM/PFM";
    }
    EXPECT_EQ(write_image(dir.at("a.png"), im, attributes), dir.at("a.png"));
    const ImageRgb png = read_image_rgb(dir.at("a.png"));
    ASSERT_EQ(png.width, 7);
    ASSERT_EQ(png.height, 5);
    EXPECT_NEAR(png.at(3, 2)[0], 64.0f / 255.0f, 1e-6f);
    write_image(dir.at("a.exr"), im, attributes);
    const ImageRgb exr = read_image_rgb(dir.at("a.exr"));
    EXPECT_EQ(exr.at(6, 4)[1], 0.5f);  // exact float
    EXPECT_EQ(read_image_attribute(dir.at("a.exr"), "sdf:config_hash"), "abc123");
    EXPECT_EQ(read_image_attribute(dir.at("a.exr"), "sdf:git_commit"), "deadbeef");
    // Never replaced silently
    EXPECT_THROW(write_image(dir.at("a.png"), im, attributes), std::exception);
    EXPECT_NO_THROW(write_image(dir.at("a.png"), im, attributes, Overwrite::Allow));
    // No temporaries left behind
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir.at(""))) files += e.is_regular_file() ? 1 : 0;
    EXPECT_EQ(files, 2);
}

TEST(ImageFiles, RenderExrKeepsEveryChannel) {
    if (!have_openimageio()) GTEST_SKIP() << "built without OpenImageIO";
    const test::ScratchDir dir("sdf_grid_test");
    RenderedImage r(3, 2);
    r.at(1, 1).hit = HitKind::Surface;
    r.at(1, 1).depth = 2.5f;
    r.at(1, 1).normal = Vec3f(0, 0.6f, 0.8f);
    r.at(1, 1).shade = 0.75f;
    write_render_exr(dir.at("r.exr"), r, {{"reconstruction", "bcc_cubic/true"}});
    EXPECT_EQ(read_image_attribute(dir.at("r.exr"), "sdf:reconstruction"), "bcc_cubic/true");
    EXPECT_EQ(read_image_rgb(dir.at("r.exr")).at(1, 1)[0], 0.75f);
}

TEST(ImageFiles, PpmAndPfmRoundTrip) {
    const test::ScratchDir dir("sdf_grid_test");
    ImageRgb im(4, 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x) im.set(x, y, x / 3.0f, y / 2.0f, 0.125f);
    write_image(dir.at("a.pfm"), im);
    write_image(dir.at("a.ppm"), im);
    const ImageRgb pfm = read_netpbm(dir.at("a.pfm"));
    EXPECT_EQ(pfm.data, im.data);  // rows flipped and back
    const ImageRgb ppm = read_netpbm(dir.at("a.ppm"));
    EXPECT_NEAR(ppm.at(3, 2)[0], 1.0f, 1e-6f);
    EXPECT_NEAR(ppm.at(0, 1)[1], 128.0f / 255.0f, 1e-6f);
}

TEST(HeatMap, ColoursErrorsAndMismatches) {
    RenderedImage a(3, 1), b(3, 1);
    for (RenderedImage* r : {&a, &b})
        for (PixelRecord& p : r->pixels) {
            p.hit = HitKind::Surface;
            p.normal = Vec3f(0, 0, 1);
        }
    a.pixels[1].normal = Vec3f(1, 0, 0);   // 90 degrees: clamped to the top of the map
    b.pixels[2].hit = HitKind::Miss;        // coverage mismatch
    const ImageRgb h = normal_error_heat_map(a, b, 10);
    float low[3], high[3];
    viridis(0, low);
    viridis(1, high);
    EXPECT_NEAR(h.at(0, 0)[0], low[0], 1e-6f);
    EXPECT_NEAR(h.at(1, 0)[1], high[1], 1e-6f);
    EXPECT_EQ(h.at(2, 0)[0], 1.0f);
    EXPECT_EQ(h.at(2, 0)[1], 0.0f);
}

TEST(ThesisFigure, FivePanelsReferenceAndErrorRowsOnASmallPawn) {
    const PreparedMesh mesh = prepare_mesh(make_pawn());
    SamplerOptions so;
    so.progress = false;
    auto sampler = make_cpu_brute_force_sampler(so);
    const SampledField cc = sampler->bind(share(mesh))->sample(fit_lattice(LatticeType::CC, {20, 20, 20}, mesh.bounds(), 0.1));
    const SampledField bcc = sampler->bind(share(mesh))->sample(fit_lattice(LatticeType::BCC, {16, 16, 16}, mesh.bounds(), 0.1));
    FigureOptions options;
    options.render.progress = false;
    options.mesh.progress = false;
    options.title = "pawn";
    const CameraSpec camera = resolve_view(named_view("front"), mesh.bounds(), 48, 64);
    const ThesisFigure f = render_thesis_figure(cc, bcc, &mesh, camera, options);
    ASSERT_EQ(f.panels.size(), 5u);
    const char* letters[] = {"A", "B", "C", "D", "E"};
    for (size_t i = 0; i < 5; ++i) {
        EXPECT_EQ(f.panels[i].spec.letter, letters[i]);
        EXPECT_TRUE(f.panels[i].has_metrics);
        EXPECT_GT(f.panels[i].metrics.hit_both, 300);
        EXPECT_LT(f.panels[i].metrics.normal_angle_degrees.mean, 30.0);
    }
    EXPECT_EQ(f.panels[1].label, "B  BCC cubic, true derivatives (16x16x32)");
    // Rows: A-C, D-E, reference + colour bar, the five heat maps at half size
    ASSERT_EQ(f.rows.size(), 4u);
    EXPECT_EQ(f.rows[0].size(), 3u);
    EXPECT_EQ(f.rows[1].size(), 2u);
    EXPECT_EQ(f.rows[2].size(), 2u);
    EXPECT_EQ(f.rows[3].size(), 5u);
    EXPECT_EQ(f.rows[3][0].image.width, 24);
    EXPECT_EQ(f.panels[4].label, "E  CC tricubic, estimated derivatives (= A) (20x20x20)");
    // The colour bar's values: 0 .. heat_max_degrees (20) in quarters, under black marks
    const GridCell& bar = f.rows[2][1];
    ASSERT_EQ(bar.ticks.size(), 5u);
    EXPECT_EQ(bar.ticks[0].text, "0");
    EXPECT_EQ(bar.ticks[2].text, "10");
    EXPECT_EQ(bar.ticks[4].text, "20");
    EXPECT_EQ(bar.ticks[4].at, 1.0);
    EXPECT_GT(bar.tick_band, 0);
    const int mark_y = bar.image.height - bar.tick_band - 1;
    for (int x : {0, int(0.5 * (bar.image.width - 1) + 0.5), bar.image.width - 1}) EXPECT_EQ(bar.image.at(x, mark_y)[0], 0.0f) << x;
    const GridLayout g = layout_grid(f.rows, f.style);
    EXPECT_EQ(f.grid.width, g.width);
    EXPECT_EQ(f.grid.height, g.height);
    EXPECT_EQ(g.width, std::max(3 * 48 + 4 * f.style.padding, 5 * 24 + 6 * f.style.padding));
    const test::ScratchDir dir("sdf_grid_test");
    const std::string grid = write_thesis_figure(dir.at(""), "pawn", f, {{"config_hash", "x"}});
    if (const char* keep = std::getenv("SDF_TEST_KEEP_GRID")) fs::copy_file(grid, keep, fs::copy_options::overwrite_existing);
    EXPECT_TRUE(fs::exists(grid));
    EXPECT_TRUE(fs::exists(dir.at("pawn_summary.json")));
    EXPECT_TRUE(fs::exists(dir.at("pawn_B_bcc_cubic_true.metrics.json")));
}

TEST(ThesisFigure, ConfiguredPanelsOnlyTheBccField) {
    // The dragon-style comparison of issue 17 at a tiny size: the thesis's BCC cubic beside the
    // quintic box spline and the linear box spline; no CC field is needed, none is given.
    const PreparedMesh mesh = prepare_mesh(make_pawn());
    SamplerOptions so;
    so.progress = false;
    auto sampler = make_cpu_brute_force_sampler(so);
    const SampledField bcc = sampler->bind(share(mesh))->sample(fit_lattice(LatticeType::BCC, {12, 12, 12}, mesh.bounds(), 0.1));
    FigureOptions options;
    options.render.progress = false;
    options.mesh.progress = false;
    options.panels = figure_panels({{"bcc_cubic", "true"}, {"bcc_box_quintic", "fd"}, {"bcc_box_linear", "fd"},
                                    {"bcc_box_quintic_qi", "fd"}});
    const CameraSpec camera = resolve_view(named_view("front"), mesh.bounds(), 24, 32);
    const ThesisFigure f = render_thesis_figure(nullptr, &bcc, &mesh, camera, options);
    ASSERT_EQ(f.panels.size(), 4u);
    EXPECT_EQ(f.panels[0].label, "A  BCC cubic, true derivatives (12x12x24)");
    EXPECT_EQ(f.panels[1].label, "B  BCC quintic box spline, interpolating (12x12x24)");
    EXPECT_EQ(f.panels[2].label, "C  BCC linear box spline (12x12x24)");
    EXPECT_EQ(f.panels[3].label, "D  BCC quintic box spline, quasi-interp. (12x12x24)");
    EXPECT_EQ(f.summary["panels"][1]["render"]["reconstruction"], "bcc_box_quintic/fd");
    for (const FigurePanel& p : f.panels) {
        EXPECT_TRUE(p.has_metrics);
        EXPECT_GT(p.metrics.hit_both, 50) << p.label;  // the pawn is there in every panel
    }
    // Rows: A-C, D, the reference + colour bar, the four heat maps
    ASSERT_EQ(f.rows.size(), 4u);
    EXPECT_EQ(f.rows[0].size(), 3u);
    EXPECT_EQ(f.rows[1].size(), 1u);
    EXPECT_EQ(f.rows[3].size(), 4u);
    EXPECT_NE(f.summary["grid"]["labels"].get<std::string>().find("B  BCC quintic box spline"), std::string::npos);
    // A CC panel without a CC field is refused, naming the panel.
    options.panels = figure_panels({{"bcc_cubic", "true"}, {"cc_bspline3", "fd"}});
    try {
        render_thesis_figure(nullptr, &bcc, nullptr, camera, options);
        ADD_FAILURE() << "a CC panel rendered without a CC field";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("panel B (cc_bspline3/fd) needs a CC field"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace sdf
