/// @file render_backend.h
/// @brief The one table of ray casters (as harness/sampling/sampler_table.h is for samplers):
/// "cpu" (cpu_reference/raycast/render_cpu.h, all cores) and "cuda" (cuda/raycast/raycast.h; this build
/// must have the CUDA backend and the machine a GPU); a request may also say "auto" (cuda when
/// available, else cpu). Both run cast_pixel. Configs, the tools and the module take their
/// choices from render_backend_choices().
#pragma once

#include <string>
#include <vector>

#include "cpu_reference/raycast/render_cpu.h"

namespace sdf {

struct RenderOptions {
    std::string backend = "cpu";  ///< "cpu", "cuda" or "auto"
    int threads = 0;              ///< cpu: 0 = all hardware threads
    bool progress = true;
    Precision precision = Precision::Float;  ///< cpu only; cuda always casts in float
    int repetitions = 1;          ///< timed renders; the median time is reported
    int device = 0;               ///< cuda device
    MarchSettings<double> march{};
};

struct RenderBackend {
    const char* name;  ///< "cpu", "cuda"
    bool on_gpu;       ///< needs a CUDA device
    /// Repeats and times its launches itself (CUDA events after a warm-up), so it is called
    /// once; the others are called once per repetition and timed here.
    bool times_own_repetitions;
    /// Null: not in this build.
    RenderedImage (*render)(const Reconstruction&, const CameraSpec&, const RenderOptions&);
};

const std::vector<RenderBackend>& render_backend_table();

/// "auto" first, then every name of the table: the choices of configs, tools and the module.
std::vector<std::string> render_backend_choices();

/// The row a requested name selects ("auto": cuda when available, else cpu); throws
/// std::invalid_argument for an unknown name or for "cuda" without the CUDA backend or a GPU.
const RenderBackend& resolve_render_backend(const std::string& requested);

/// Bounds of a field's solid, for framing a view without the mesh: the lattice points with
/// f <= 0, grown by one spacing. Throws when no point has f <= 0 (nothing to frame).
Bounds3 field_solid_bounds(const SampledField& field);

/// True when this build has the CUDA ray caster and a GPU is present.
bool cuda_render_available();

/// Renders `camera` through the reconstruction. info gains "reconstruction", "camera",
/// "march" statistics and "seconds": cpu, the median wall time of `repetitions` render calls
/// (float copy of the data included; "cast_seconds" is the last call's pixel loop alone);
/// cuda, the wall time of the one call (upload, warm-up, `repetitions` timed launches,
/// download), whose "kernel_seconds" is the median CUDA-event time of one launch.
RenderedImage render_reconstruction(const Reconstruction& reconstruction, const CameraSpec& camera,
                                    const RenderOptions& options = {});

}  // namespace sdf
