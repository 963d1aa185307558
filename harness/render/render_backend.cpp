#include "harness/render/render_backend.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "core/quoted_alternatives.h"
#include "core/statistics.h"
#include "harness/sampling/sampler_table.h"

#if SDF_HAVE_CUDA_RAYCAST
#include "cuda/raycast/raycast.h"
#endif

namespace sdf {

Bounds3 field_solid_bounds(const SampledField& f) {
    Bounds3 b;
    for (int64_t i = 0; i < f.size(); ++i)
        if (f.distance[size_t(i)] <= 0) b.extend(f.lattice.position(i));
    if (b.empty()) throw std::runtime_error("the field has no point with a value <= 0: nothing to frame");
    b.extend(b.min - Vec3d(f.lattice.spacing));
    b.extend(b.max + Vec3d(f.lattice.spacing));
    return b;
}
namespace {

RenderedImage render_cpu(const Reconstruction& r, const CameraSpec& camera, const RenderOptions& o) {
    CpuRenderOptions c;
    c.threads = o.threads;
    c.progress = o.progress;
    c.precision = o.precision;
    c.march = o.march;
    return render_reconstruction_cpu(r, camera, c);
}

#if SDF_HAVE_CUDA_RAYCAST
RenderedImage render_cuda(const Reconstruction& r, const CameraSpec& camera, const RenderOptions& o) {
    cuda::CudaRaycastOptions c;
    c.device = o.device;
    c.repetitions = o.repetitions;
    c.march = o.march;
    const HermiteData<float> data = convert_hermite_data<float>(r.data());
    RenderedImage image = cuda::render_field_view_cuda(data.view(), r.spec().interpolator, make_camera(camera), c);
    image.info["reconstruction"] = r.description();
    image.info["camera"] = camera_to_json(camera);
    image.info["march"] = march_statistics(image);
    return image;
}
#else
constexpr RenderedImage (*render_cuda)(const Reconstruction&, const CameraSpec&, const RenderOptions&) = nullptr;
#endif

}  // namespace

const std::vector<RenderBackend>& render_backend_table() {
    static const std::vector<RenderBackend> table = {
        {"cpu", false, false, render_cpu},
        {"cuda", true, true, render_cuda},
    };
    return table;
}

std::vector<std::string> render_backend_choices() {
    std::vector<std::string> names = {"auto"};
    for (const RenderBackend& b : render_backend_table()) names.emplace_back(b.name);
    return names;
}

bool cuda_render_available() {
#if SDF_HAVE_CUDA_RAYCAST
    return cuda_backend_available();
#else
    return false;
#endif
}

const RenderBackend& resolve_render_backend(const std::string& requested) {
    const std::vector<RenderBackend>& table = render_backend_table();
    const std::string name = requested == "auto" ? (cuda_render_available() ? "cuda" : "cpu") : requested;
    const auto row = std::find_if(table.begin(), table.end(), [&](const RenderBackend& b) { return name == b.name; });
    if (row == table.end())
        throw std::invalid_argument("render backend '" + requested + "': expected " +
                                    quoted_alternatives(render_backend_choices()));
    if (row->render == nullptr || (row->on_gpu && !cuda_render_available()))
        throw std::invalid_argument("render backend '" + name + "': " +
                                    (row->render ? "no CUDA device on this machine" : "this build has no CUDA backend") +
                                    "; use 'cpu' or 'auto'");
    return *row;
}

RenderedImage render_reconstruction(const Reconstruction& reconstruction, const CameraSpec& camera,
                                    const RenderOptions& options) {
    if (options.repetitions < 1)
        throw std::invalid_argument("render: repetitions must be >= 1, got " + std::to_string(options.repetitions));
    const RenderBackend& backend = resolve_render_backend(options.backend);
    const int calls = backend.times_own_repetitions ? 1 : options.repetitions;
    std::vector<double> seconds;
    RenderedImage image;
    for (int i = 0; i < calls; ++i) {
        const auto start = std::chrono::steady_clock::now();
        image = backend.render(reconstruction, camera, options);
        if (!backend.times_own_repetitions) image.info["cast_seconds"] = image.info["seconds"];  // the pixel loop alone
        seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    image.info["seconds"] = median_of(seconds);
    image.info["seconds_all"] = seconds;
    return image;
}

}  // namespace sdf
