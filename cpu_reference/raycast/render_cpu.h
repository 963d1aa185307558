/// @file render_cpu.h
/// @brief The CPU ray caster of a Reconstruction: cast_pixel (kernels/raycast/cast_pixel.h)
/// over 16x16 tiles on all cores, with progress lines. The CUDA ray caster
/// (cuda/raycast/raycast.h) runs the same cast_pixel, one thread per pixel.
///
/// The ray caster knows a Reconstruction (its interpolator and Hermite data), not how the
/// field was sampled. By default it casts in float, as the GPU does, from the float copy of
/// the Hermite data (convert_hermite_data<float>), so the two backends agree pixel for pixel
/// up to the contraction of multiply-adds; Precision::Double casts from the double data.
#pragma once

#include "core/raycast/rendered_image.h"
#include "core/raycast/views.h"
#include "core/reconstruction/reconstruction.h"
#include "kernels/raycast/march.h"

namespace sdf {

struct CpuRenderOptions {
    int threads = 0;      ///< 0 = all hardware threads
    bool progress = true;
    Precision precision = Precision::Float;
    MarchSettings<double> march{};
    int tile = 16;
};

/// Casts every pixel of `camera`. info holds "renderer", "backend", "precision",
/// "threads", "reconstruction", "camera", "seconds" (the pixel loop) and "setup_seconds"
/// (the float copy of the data), and march statistics.
RenderedImage render_reconstruction_cpu(const Reconstruction& reconstruction, const CameraSpec& camera,
                                        const CpuRenderOptions& options = {});

/// The same from a view and an interpolator kind (the view's arrays must fit the kind).
template <typename T>
RenderedImage render_field_view_cpu(const LatticeFieldView<T>& view, InterpolatorKind kind, const CameraSpec& camera,
                                    const CpuRenderOptions& options = {});

/// Step and refinement totals of an image (mean steps per pixel, hits) for the info block.
nlohmann::json march_statistics(const RenderedImage& image);

}  // namespace sdf
