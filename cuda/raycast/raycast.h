/// @file raycast.h
/// @brief The CUDA ray caster: cast_pixel (kernels/raycast/cast_pixel.h), the same code the
/// CPU driver runs, one thread per pixel in 16x8 blocks, from the float Hermite data of a
/// reconstruction uploaded to the device. Host interface only (no CUDA types), so the
/// harness can call it from plain C++.
#pragma once

#include "core/raycast/rendered_image.h"
#include "kernels/raycast/march.h"
#include "kernels/reconstruction/interpolators.h"

namespace sdf::cuda {

struct CudaRaycastOptions {
    int device = 0;
    /// Timed launches after one warm-up launch; the image is the last launch's. The median
    /// kernel time (CUDA events) is reported as info["kernel_seconds"].
    int repetitions = 1;
    MarchSettings<double> march{};
};

/// Uploads the arrays `view` points to (host memory: values, first and higher derivatives,
/// sized by view.lattice.num_points()), casts every pixel of `camera` with interpolator
/// `kind` and downloads the records. info holds "renderer", "backend" ("cuda"), "device",
/// "interpolator", "repetitions", "kernel_seconds" (median), "kernel_seconds_min",
/// "kernel_seconds_all", "upload_seconds", "download_seconds" and march statistics are left
/// to the caller. Throws std::runtime_error naming the CUDA call or kernel on failure.
RenderedImage render_field_view_cuda(const LatticeFieldView<float>& view, InterpolatorKind kind,
                                     const PinholeCamera<double>& camera, const CudaRaycastOptions& options = {});

}  // namespace sdf::cuda
