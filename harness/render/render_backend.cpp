#include "harness/render/render_backend.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "harness/sampling/sampler_table.h"

#if SDF_HAVE_CUDA_RAYCAST
#include "cuda/raycast.h"
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

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

RenderedImage render_once(const Reconstruction& r, const CameraSpec& camera, const RenderOptions& o,
                          const std::string& backend) {
    if (backend == "cpu") {
        CpuRenderOptions c;
        c.threads = o.threads;
        c.progress = o.progress;
        c.precision = o.precision;
        c.march = o.march;
        return render_reconstruction_cpu(r, camera, c);
    }
#if SDF_HAVE_CUDA_RAYCAST
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
#else
    throw std::invalid_argument("render backend '" + backend + "': this build has no CUDA backend");
#endif
}

}  // namespace

bool cuda_render_available() {
#if SDF_HAVE_CUDA_RAYCAST
    return cuda_backend_available();
#else
    return false;
#endif
}

std::string resolve_render_backend(const std::string& requested) {
    if (requested == "cpu") return "cpu";
    if (requested == "auto") return cuda_render_available() ? "cuda" : "cpu";
    if (requested == "cuda") {
        if (!cuda_render_available())
            throw std::invalid_argument(std::string("render backend 'cuda': ") +
                                        (SDF_HAVE_CUDA_RAYCAST ? "no CUDA device on this machine"
                                                               : "this build has no CUDA backend") +
                                        "; use 'cpu' or 'auto'");
        return "cuda";
    }
    throw std::invalid_argument("render backend '" + requested + "': expected cpu, cuda or auto");
}

RenderedImage render_reconstruction(const Reconstruction& reconstruction, const CameraSpec& camera,
                                    const RenderOptions& options) {
    if (options.repetitions < 1)
        throw std::invalid_argument("render: repetitions must be >= 1, got " + std::to_string(options.repetitions));
    const std::string backend = resolve_render_backend(options.backend);
    // The CUDA launcher repeats the kernel itself; the CPU renders repeat here
    const int calls = backend == "cpu" ? options.repetitions : 1;
    std::vector<double> seconds;
    RenderedImage image;
    for (int i = 0; i < calls; ++i) {
        const auto start = std::chrono::steady_clock::now();
        image = render_once(reconstruction, camera, options, backend);
        if (backend == "cpu") image.info["cast_seconds"] = image.info["seconds"];  // the pixel loop alone
        seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    image.info["seconds"] = median(seconds);
    image.info["seconds_all"] = seconds;
    return image;
}

}  // namespace sdf
