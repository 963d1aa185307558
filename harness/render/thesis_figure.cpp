#include "harness/render/thesis_figure.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "core/lattice/lattice_fitting.h"
#include "core/reconstruction/reconstruction_spec.h"
#include "harness/render/heat_map.h"
#include "harness/render/image_io.h"

namespace sdf {
namespace {

std::string fixed(double v, int digits) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(digits);
    s << v;
    return s.str();
}

std::string panel_label(const FigurePanelSpec& p, const Lattice& lattice) {
    return p.letter + "  " + p.caption + " (" + lattice_notation(lattice) + ")";
}

std::string panel_file_stem(const std::string& name, const FigurePanelSpec& p) {
    return name + "_" + p.letter + "_" + p.interpolator + "_" + p.derivatives;
}

ImageRgb reduced(const ImageRgb& image, int factor) { return factor > 1 ? downsample(image, factor) : image; }

std::string percent(double fraction) { return fixed(100.0 * fraction, 2) + "%"; }

/// The heat maps' colour bar with its values at 0, 1/4, .. 1 of the scale.
GridCell heat_map_legend(int width, double max_degrees) {
    constexpr int kTicks = 4;
    const int text_band = std::max(12, width / 12);
    GridCell c{colour_bar_with_ticks(width, std::max(8, width / 16), kTicks, text_band),
               "normal error (deg); below: mean / p95, % coverage"};
    const double step = max_degrees / kTicks;
    const int digits = step == std::floor(step) ? 0 : 1;
    for (int t = 0; t <= kTicks; ++t) c.ticks.push_back({double(t) / kTicks, fixed(t * step, digits)});
    c.tick_band = text_band;
    return c;
}

std::vector<GridRow> figure_rows(const ThesisFigure& f, const FigureOptions& o) {
    std::vector<GridCell> renders;
    GridRow errors;
    for (const FigurePanel& p : f.panels) {
        renders.push_back({reduced(shaded_image(p.image), o.downsample), p.label});
        if (o.error_rows && f.has_reference)
            errors.push_back({reduced(normal_error_heat_map(p.image, f.reference, o.heat_max_degrees), 2 * o.downsample),
                              p.spec.letter + ": " + fixed(p.metrics.normal_angle_degrees.mean, 1) + " / " +
                                  fixed(p.metrics.normal_angle_degrees.p95, 1) + " deg, " +
                                  percent(p.metrics.coverage_mismatch_fraction)});
    }
    std::vector<GridRow> rows;
    for (size_t i = 0; i < renders.size(); ++i) {
        if (i % kPanelsPerRow == 0) rows.emplace_back();
        rows.back().push_back(renders[i]);
    }
    if (o.reference_row && f.has_reference) {
        GridRow r{{reduced(shaded_image(f.reference), o.downsample), "Reference: the mesh, ray-traced"}};
        if (!errors.empty()) {
            r.push_back(heat_map_legend(r[0].image.width, o.heat_max_degrees));
        }
        rows.push_back(r);
    }
    if (!errors.empty()) rows.push_back(errors);
    return rows;
}

nlohmann::json with(const nlohmann::json& base, const nlohmann::json& extra) {
    nlohmann::json j = base.is_object() ? base : nlohmann::json::object();
    for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
    return j;
}

}  // namespace

std::vector<FigurePanelSpec> thesis_figure_panels() {
    return {{"A", LatticeType::CC, "catmull_rom", "fd", "Catmull-Rom"},
            {"B", LatticeType::BCC, "bcc_cubic", "true", "BCC cubic, true derivatives"},
            {"C", LatticeType::BCC, "bcc_cubic", "fd", "BCC cubic, estimated derivatives"},
            {"D", LatticeType::CC, "tricubic_lm", "true", "CC tricubic, true derivatives"},
            // tricubic_lm with central differences is Catmull-Rom (docs/reconstruction.md); a short
            // mark, since a row's labels share the size at which the longest fits
            {"E", LatticeType::CC, "tricubic_lm", "fd", "CC tricubic, estimated derivatives (= A)"}};
}

namespace {

/// Captions by interpolator (and derivative source where it matters); filters without one
/// are captioned with their name.
struct CaptionRow {
    const char* interpolator;
    const char* derivatives;  ///< "" = any
    const char* caption;
};
constexpr CaptionRow kCaptions[] = {
    {"trilinear", "", "Trilinear"},
    {"catmull_rom", "", "Catmull-Rom"},
    {"tricubic_lm", "true", "CC tricubic, true derivatives"},
    {"tricubic_lm", "fd", "CC tricubic, estimated derivatives"},
    {"cc_bspline3", "", "CC cubic B-spline, prefiltered"},
    {"bcc_linear", "", "BCC linear"},
    {"bcc_cubic", "true", "BCC cubic, true derivatives"},
    {"bcc_cubic", "fd", "BCC cubic, estimated derivatives"},
    {"bcc_cubic", "fd_weighted", "BCC cubic, weighted estimate"},
    {"bcc_cubic_c0", "true", "BCC cubic C0, true derivatives"},
    {"bcc_cubic_c0", "fd", "BCC cubic C0, estimated derivatives"},
    {"bcc_cubic_c0", "fd_weighted", "BCC cubic C0, weighted estimate"},
    {"bcc_box_linear", "", "BCC linear box spline"},
    {"bcc_box_quintic", "", "BCC quintic box spline, interpolating"},
    {"bcc_box_quintic_qi", "", "BCC quintic box spline, quasi-interp."},
    {"bcc_box_quintic_approx", "", "BCC quintic box spline, approximating"},
};

}  // namespace

std::string panel_caption(const std::string& interpolator, const std::string& derivatives) {
    for (const CaptionRow& c : kCaptions)
        if (interpolator == c.interpolator && (c.derivatives[0] == '\0' || derivatives == c.derivatives)) return c.caption;
    return interpolator + "/" + derivatives;
}

std::vector<FigurePanelSpec> figure_panels(const std::vector<RenderPanelRequest>& requests) {
    if (requests.size() > 26) throw std::invalid_argument("figure panels: at most 26 (letters A..Z), got " + std::to_string(requests.size()));
    std::vector<FigurePanelSpec> out;
    for (const RenderPanelRequest& r : requests)
        out.push_back({std::string(1, char('A' + out.size())), interpolator_lattice(parse_interpolator(r.interpolator)),
                       r.interpolator, r.derivatives, panel_caption(r.interpolator, r.derivatives)});
    return out;
}

FigureOptions figure_options(const RenderSpec& spec) {
    FigureOptions o;
    o.panels = figure_panels(spec.panels);
    o.render = render_options(spec);
    o.reference_row = spec.reference;
    o.error_rows = spec.reference && spec.error_maps;
    o.heat_max_degrees = spec.heat_max_degrees;
    o.downsample = spec.grid_downsample;
    return o;
}

ThesisFigure render_thesis_figure(const SampledField& cc, const SampledField& bcc, const PreparedMesh* mesh,
                                  const CameraSpec& camera, const FigureOptions& options) {
    return render_thesis_figure(&cc, &bcc, mesh, camera, options);
}

ThesisFigure render_thesis_figure(const SampledField* cc, const SampledField* bcc, const PreparedMesh* mesh,
                                  const CameraSpec& camera, const FigureOptions& options) {
    ThesisFigure f;
    f.camera = camera;
    f.summary["camera"] = camera_to_json(camera);
    if (mesh) {
        f.reference = MeshReferenceRenderer(*mesh).render(camera, options.mesh);
        f.has_reference = true;
        f.summary["reference"] = f.reference.info;
    }
    for (const FigurePanelSpec& spec : options.panels.empty() ? thesis_figure_panels() : options.panels) {
        const SampledField* chosen = spec.lattice == LatticeType::CC ? cc : bcc;
        if (!chosen || chosen->lattice.type != spec.lattice)
            throw std::invalid_argument("thesis figure: panel " + spec.letter + " (" + spec.interpolator + "/" +
                                        spec.derivatives + ") needs a " +
                                        lattice_type_label(spec.lattice) + " field");
        const SampledField& field = *chosen;
        FigurePanel p;
        p.spec = spec;
        p.label = panel_label(spec, field.lattice);
        const Reconstruction recon(field, spec.interpolator, spec.derivatives);
        p.image = render_reconstruction(recon, camera, options.render);
        p.image.info["lattice"] = lattice_notation(field.lattice);
        nlohmann::json entry = {{"letter", spec.letter}, {"label", p.label}, {"render", p.image.info}};
        if (f.has_reference) {
            p.metrics = compare_images(p.image, f.reference, field.lattice.spacing);
            p.has_metrics = true;
            entry["metrics"] = metrics_to_json(p.metrics);
        }
        std::fprintf(stderr, "  %s %s: %.2f s%s\n", spec.letter.c_str(), recon.description().c_str(),
                     p.image.info["seconds"].get<double>(),
                     p.has_metrics ? (", normal error mean " + fixed(p.metrics.normal_angle_degrees.mean, 2) + " deg")
                                         .c_str()
                                   : "");
        f.summary["panels"].push_back(entry);
        f.panels.push_back(std::move(p));
    }
    f.style.title = options.title;
    f.rows = figure_rows(f, options);
    f.grid = make_image_grid(f.rows, f.style);
    f.summary["grid"] = {{"size", {f.grid.width, f.grid.height}},
                         {"downsample", options.downsample},
                         {"heat_max_degrees", options.heat_max_degrees},
                         {"labels", label_grid_text(f.rows, f.style)}};
    return f;
}

std::string write_thesis_figure(const std::string& dir, const std::string& name, const ThesisFigure& figure,
                                const nlohmann::json& provenance, Overwrite overwrite) {
    const std::string base = dir + "/" + name;
    for (const FigurePanel& p : figure.panels) {
        const std::string stem = dir + "/" + panel_file_stem(name, p.spec);
        const nlohmann::json attributes =
            with(provenance, {{"render_seconds", p.image.info.value("seconds", 0.0)},
                              {"reconstruction", p.image.info.value("reconstruction", std::string())},
                              {"lattice", p.image.info.value("lattice", std::string())},
                              {"camera", camera_to_json(figure.camera)},
                              {"backend", p.image.info.value("backend", std::string())}});
        write_image(stem + ".png", shaded_image(p.image), attributes, overwrite);
        write_render_exr(stem + ".exr", p.image, attributes, overwrite);
        if (p.has_metrics) write_text_atomically(stem + ".metrics.json", metrics_to_json(p.metrics).dump(2) + "\n", overwrite);
    }
    if (figure.has_reference) {
        const nlohmann::json attributes =
            with(provenance, {{"render_seconds", figure.reference.info.value("seconds", 0.0)},
                              {"reconstruction", "mesh reference"},
                              {"camera", camera_to_json(figure.camera)}});
        write_image(base + "_reference.png", shaded_image(figure.reference), attributes, overwrite);
        write_render_exr(base + "_reference.exr", figure.reference, attributes, overwrite);
    }
    nlohmann::json seconds = nlohmann::json::object();
    for (const FigurePanel& p : figure.panels) seconds[p.spec.letter] = p.image.info.value("seconds", 0.0);
    if (figure.has_reference) seconds["reference"] = figure.reference.info.value("seconds", 0.0);
    const nlohmann::json grid_attributes = with(provenance, {{"camera", camera_to_json(figure.camera)},
                                                             {"render_seconds", seconds},
                                                             {"labels", label_grid_text(figure.rows, figure.style)}});
    const std::string grid = write_image(base + "_grid.png", figure.grid, grid_attributes, overwrite);
    write_image(base + "_grid.exr", figure.grid, grid_attributes, overwrite);
    write_text_atomically(base + "_summary.json", with(figure.summary, {{"provenance", provenance}}).dump(2) + "\n",
                          overwrite);
    return grid;
}

}  // namespace sdf
