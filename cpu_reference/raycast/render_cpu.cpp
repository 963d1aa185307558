#include "cpu_reference/raycast/render_cpu.h"

#include <chrono>

#include "core/parallel/parallel_for.h"
#include "cpu_reference/raycast/tile_loop.h"
#include "kernels/raycast/cast_pixel.h"

namespace sdf {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

template <typename Interp, typename T>
void cast_tiles(const RaycastScene<T>& scene, const CpuRenderOptions& options, RenderedImage& image) {
    const std::string label = std::string("render ") + Interp::name();
    for_each_tile(image.width, image.height, options.tile, options.threads, label, options.progress,
                  [&](int x0, int y0, int x1, int y1) {
                      for (int y = y0; y < y1; ++y)
                          for (int x = x0; x < x1; ++x) image.at(x, y) = cast_pixel<Interp>(scene, x, y);
                  });
}

}  // namespace

template <typename T>
RenderedImage render_field_view_cpu(const LatticeFieldView<T>& view, InterpolatorKind kind, const CameraSpec& camera,
                                    const CpuRenderOptions& options) {
    const PinholeCamera<T> pinhole = make_camera(camera).template as<T>();
    RenderedImage image(camera.width, camera.height);
    const auto start = std::chrono::steady_clock::now();
    visit_interpolator(kind, [&](auto interp) {
        using Interp = decltype(interp);
        const RaycastScene<T> scene = make_raycast_scene<Interp>(view, pinhole, options.march.template as<T>());
        cast_tiles<Interp>(scene, options, image);
        return 0;
    });
    image.info = {{"renderer", "raycast"},
                  {"backend", "cpu"},
                  {"precision", sizeof(T) == 4 ? "float" : "double"},
                  {"threads", resolve_thread_count(options.threads)},
                  {"interpolator", interpolator_name(kind)},
                  {"camera", camera_to_json(camera)},
                  {"seconds", seconds_since(start)},
                  {"march", march_statistics(image)}};
    return image;
}

template RenderedImage render_field_view_cpu<float>(const LatticeFieldView<float>&, InterpolatorKind,
                                                    const CameraSpec&, const CpuRenderOptions&);
template RenderedImage render_field_view_cpu<double>(const LatticeFieldView<double>&, InterpolatorKind,
                                                     const CameraSpec&, const CpuRenderOptions&);

RenderedImage render_reconstruction_cpu(const Reconstruction& reconstruction, const CameraSpec& camera,
                                        const CpuRenderOptions& options) {
    const InterpolatorKind kind = reconstruction.spec().interpolator;
    RenderedImage image;
    double setup = 0;
    if (options.precision == Precision::Double) {
        image = render_field_view_cpu(reconstruction.view(), kind, camera, options);
    } else {
        const auto start = std::chrono::steady_clock::now();
        const HermiteData<float> data = convert_hermite_data<float>(reconstruction.data());
        setup = seconds_since(start);
        image = render_field_view_cpu(data.view(), kind, camera, options);
    }
    image.info["reconstruction"] = reconstruction.description();
    image.info["setup_seconds"] = setup;
    return image;
}

nlohmann::json march_statistics(const RenderedImage& image) {
    int64_t steps = 0, refine = 0, hits = 0, clipped = 0, max_steps = 0;
    for (const PixelRecord& p : image.pixels) {
        steps += p.steps;
        refine += p.refine_iterations;
        hits += p.is_hit() ? 1 : 0;
        clipped += p.hit == HitKind::Clipped ? 1 : 0;
        max_steps = p.steps > max_steps ? p.steps : max_steps;
    }
    const double n = image.pixels.empty() ? 1.0 : double(image.pixels.size());
    return {{"hits", hits},
            {"clipped", clipped},
            {"mean_steps", double(steps) / n},
            {"max_steps", max_steps},
            {"mean_refine_iterations", hits > 0 ? double(refine) / double(hits) : 0.0}};
}

}  // namespace sdf
