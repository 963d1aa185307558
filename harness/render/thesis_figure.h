/// @file thesis_figure.h
/// @brief One figure in the layout of the thesis's Figures 5-2 to 5-11: five reconstructions
/// of a mesh's distance field rendered from one camera and assembled into a labelled grid,
/// with optional rows for the mesh reference and for normal-error heat maps, and the image
/// metrics of every panel against the reference (docs/raycast.md, "Grids").
///
///   row 1:  A catmull_rom (CC)   B bcc_cubic, true derivatives   C bcc_cubic, fd
///   row 2:  D tricubic_lm, true derivatives (CC)   E tricubic_lm, fd (CC)
///   row 3:  the mesh reference, and the heat maps' colour bar         (reference_row)
///   row 4:  normal error of A..E against the reference at half size, with mean / p95
///           angle and the coverage mismatch as a percentage of the pixels (error_rows)
///
/// FigureOptions::panels replaces the five by any reconstructions of the interpolator table
/// (the config's "render": {"panels": [...]}, render_spec.h), three per row, lettered A, B, ...
#pragma once

#include <string>
#include <vector>

#include "core/raycast/image_metrics.h"
#include "cpu_reference/raycast/mesh_reference.h"
#include "harness/config/render_spec.h"
#include "harness/io/atomic_file.h"
#include "harness/render/image_grid.h"
#include "harness/render/render_backend.h"

namespace sdf {

/// One panel: which lattice, interpolator and derivative source.
struct FigurePanelSpec {
    std::string letter;
    LatticeType lattice = LatticeType::CC;
    std::string interpolator, derivatives;
    std::string caption;  ///< "Catmull-Rom", "BCC cubic, true derivatives", ...
};

/// The thesis's five panels, in order A..E; row 1 is A-C, row 2 is D-E.
std::vector<FigurePanelSpec> thesis_figure_panels();

/// Panels for the requested reconstructions, lettered A, B, ... in order, captioned from the
/// table of captions (the filter's name where it has none), on the lattice of their filter.
std::vector<FigurePanelSpec> figure_panels(const std::vector<RenderPanelRequest>& requests);

/// "BCC quintic box spline (interpolating)", "CC tricubic, true derivatives", ...
std::string panel_caption(const std::string& interpolator, const std::string& derivatives);

/// Panels per row of the grid.
constexpr int kPanelsPerRow = 3;

struct FigureOptions {
    RenderOptions render{};
    MeshRenderOptions mesh{};
    bool reference_row = true;   ///< needs a mesh
    bool error_rows = true;      ///< needs a mesh
    double heat_max_degrees = 20;
    std::string title;
    int downsample = 1;          ///< grid images reduced by this factor (1 = full size)
    std::vector<FigurePanelSpec> panels;  ///< empty: thesis_figure_panels()
};

/// The options a config's "render" block asks for (backend, precision, rows, heat-map scale,
/// downsampling); threads and progress keep their defaults.
FigureOptions figure_options(const RenderSpec& spec);

struct FigurePanel {
    FigurePanelSpec spec;
    std::string label;           ///< as drawn under the image
    RenderedImage image;
    bool has_metrics = false;
    ImageMetrics metrics;        ///< against the reference
};

struct ThesisFigure {
    CameraSpec camera;
    std::vector<FigurePanel> panels;
    bool has_reference = false;
    RenderedImage reference;
    GridStyle style;
    std::vector<GridRow> rows;
    ImageRgb grid;
    nlohmann::json summary;      ///< camera, panels (reconstruction, lattice, timings, metrics)
};

/// Renders the panels (cc: a CC field with gradients; bcc: a BCC one) and, when `mesh` is
/// given, the reference and the metrics; assembles the grid.
ThesisFigure render_thesis_figure(const SampledField& cc, const SampledField& bcc, const PreparedMesh* mesh,
                                  const CameraSpec& camera, const FigureOptions& options);
/// The same with either field absent (null): only panels whose lattice type is present may be
/// asked for (std::invalid_argument naming the panel otherwise).
ThesisFigure render_thesis_figure(const SampledField* cc, const SampledField* bcc, const PreparedMesh* mesh,
                                  const CameraSpec& camera, const FigureOptions& options);

/// Writes into `dir` (which must exist): NAME_grid.png and NAME_grid.exr; per panel
/// NAME_<letter>_<interpolator>_<derivatives>.png, .exr (all channels) and .metrics.json;
/// NAME_reference.png/.exr; NAME_summary.json. `provenance` becomes the EXR/PNG attributes
/// (with render_seconds and reconstruction/camera added per image). Returns the grid path.
std::string write_thesis_figure(const std::string& dir, const std::string& name, const ThesisFigure& figure,
                                const nlohmann::json& provenance, Overwrite overwrite = Overwrite::Forbid);

}  // namespace sdf
