/// @file render_backend.h
/// @brief The one place that maps a render backend name to an implementation (as
/// harness/sampling/sampler_table.h does for samplers): "cpu" (cpu_reference/raycast/render_cpu.h, all
/// cores), "cuda" (cuda/raycast.h; this build must have the CUDA backend and the
/// machine a GPU), or "auto" (cuda when available, else cpu). Both run cast_pixel.
#pragma once

#include <string>

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

/// "cpu" or "cuda" for a requested name; throws std::invalid_argument for an unknown name
/// or for "cuda" without the CUDA backend or a GPU.
std::string resolve_render_backend(const std::string& requested);

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
