/// @file render_spec.h
/// @brief The render options (RenderSpec) and their one JSON codec, the "render" block of a
/// config: image size, views, reference and error rows, backend (docs/raycast.md, "Config").
/// The reconstruction experiment reads a config's block with it, and sdf-render turns its
/// flags into such a block (render_spec_from_json), so both get the same checks, defaults
/// and messages; render_spec_to_json writes every field back.
///
///   "render": {
///     "size": [512, 512],              // or one integer for a square image; default 512
///     "views": ["dragon_side", "dragon_front",          // named views fitted to the mesh
///               {"name": "closeup", "eye": [0, 0.2, 0.4], "target": [0, 0.12, 0],
///                "up": [0, 1, 0], "fov": 20},          // an explicit camera
///               {"view": "front", "fov": 20, "margin": 0.1}],  // a named view, adjusted
///     "fov": 30,                       // default vertical fov of named views, degrees
///     "margin": 0.04,                  // default free border of named views (fraction)
///     "reference": true,               // render the mesh reference (ground truth) and metrics
///     "error_maps": true,              // heat-map rows in the grid
///     "heat_max_degrees": 20,          // heat-map scale
///     "backend": "auto",               // cpu, cuda or auto
///     "precision": "float",            // cpu casts in float (as the GPU) or double
///     "grid_downsample": 1,            // grid images reduced by this factor
///     "panels": ["bcc_cubic/true", "bcc_box_quintic", "cc_bspline3"]
///                                      // the reconstructions in the grid, in order, three per
///                                      // row, lettered A, B, ...: "interpolator" (its default
///                                      // derivatives) or "interpolator/derivatives", any filter
///                                      // of the interpolator table, on the first lattice of its
///                                      // type; default: the thesis's five (A..E)
///   }
/// Named views: views.h (front, back, side, right, left, top, bottom, three_quarter,
/// dragon_side, dragon_front). Every key is optional; unknown keys are rejected.
#pragma once

#include <string>
#include <vector>

#include "core/raycast/views.h"
#include "harness/config/json_reader.h"
#include "harness/render/render_backend.h"

namespace sdf {

/// One panel of the figure grid: a filter of the interpolator table and its derivative source
/// (names as in configs; checked against the table when parsed).
struct RenderPanelRequest {
    std::string interpolator, derivatives;
};

struct RenderSpec {
    int width = 512, height = 512;
    std::vector<ViewRequest> views{named_view("three_quarter")};
    bool reference = true;
    bool error_maps = true;
    double heat_max_degrees = 20;
    std::string backend = "auto";
    std::string precision = "float";
    int grid_downsample = 1;
    std::vector<RenderPanelRequest> panels;  ///< empty: the thesis's five
};

/// "interpolator" (its default derivative source: "true" where it reads derivatives, else
/// "fd") or "interpolator/derivatives", checked against the interpolator table; throws
/// std::invalid_argument quoting the text and saying what is expected.
RenderPanelRequest parse_panel_request(const std::string& text);

/// Reads a "render" object (r reads that object, e.g. config.optional_object("render")) and
/// calls r.finish(). Errors name the file, the key path, the value and what was expected.
RenderSpec parse_render_spec(JsonReader& r);

/// The same for a "render" object from elsewhere (sdf-render's command line); errors name
/// `source` and the key.
RenderSpec render_spec_from_json(const nlohmann::json& j, const std::string& source);

/// Every field, as the "render" object render_spec_from_json reads back to the same spec
/// (views as {"view", "fov", "margin"[, "name"]} or explicit cameras, panels as
/// "interpolator/derivatives").
nlohmann::json render_spec_to_json(const RenderSpec& s);

/// The ray caster's options the spec decides (backend, precision); threads, progress,
/// repetitions and device keep RenderOptions' defaults for the caller to set.
RenderOptions render_options(const RenderSpec& s);

}  // namespace sdf
