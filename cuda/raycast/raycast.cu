#include "cuda/raycast/raycast.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/statistics.h"
#include "cuda/util/cuda_device.h"
#include "cuda/util/device_buffer.h"
#include "kernels/raycast/cast_pixel.h"

namespace sdf::cuda {
namespace {

constexpr int kBlockX = 16, kBlockY = 8;

template <typename Interp>
__global__ void raycast_kernel(const RaycastScene<float> scene, PixelRecord* __restrict__ out) {
    const int x = int(blockIdx.x) * kBlockX + int(threadIdx.x);
    const int y = int(blockIdx.y) * kBlockY + int(threadIdx.y);
    if (x >= scene.camera.width || y >= scene.camera.height) return;
    out[int64_t(y) * scene.camera.width + x] = cast_pixel<Interp>(scene, x, y);
}

/// The view's arrays on the device, and the view that points at them.
class DeviceFieldView {
public:
    explicit DeviceFieldView(const LatticeFieldView<float>& host) : view_(host) {
        const size_t n = size_t(host.lattice.num_points());
        values_.upload(host.values, n);
        view_.values = values_.get();
        if (host.first) {
            first_.upload(host.first, n);
            view_.first = first_.get();
        }
        if (host.higher && host.higher_stride > 0) {
            higher_.upload(host.higher, n * size_t(host.higher_stride));
            view_.higher = higher_.get();
        }
    }
    const LatticeFieldView<float>& view() const { return view_; }

private:
    LatticeFieldView<float> view_;
    DeviceBuffer<float> values_;
    DeviceBuffer<Vec3f> first_;
    DeviceBuffer<float> higher_;
};

template <typename Interp>
std::vector<double> launch_timed(const RaycastScene<float>& scene, PixelRecord* out, int repetitions) {
    const dim3 block(kBlockX, kBlockY);
    const dim3 grid((scene.camera.width + kBlockX - 1) / kBlockX, (scene.camera.height + kBlockY - 1) / kBlockY);
    std::vector<double> seconds;
    for (int r = -1; r < repetitions; ++r) {  // r = -1: warm-up, not timed
        EventTimer timer;
        timer.begin();
        raycast_kernel<Interp><<<grid, block>>>(scene, out);
        try {
            CUDA_CHECK_LAUNCH("raycast_kernel");
        } catch (const std::runtime_error& e) {
            throw std::runtime_error(std::string(e.what()) + " (interpolator " + Interp::name() + ")");
        }
        timer.end();
        if (r >= 0) seconds.push_back(timer.seconds());
    }
    return seconds;
}

}  // namespace

RenderedImage render_field_view_cuda(const LatticeFieldView<float>& view, InterpolatorKind kind,
                                     const PinholeCamera<double>& camera, const CudaRaycastOptions& options) {
    if (options.repetitions < 1)
        throw std::invalid_argument("render_field_view_cuda: repetitions must be >= 1, got " +
                                    std::to_string(options.repetitions));
    const DeviceGuard on_device(options.device);
    RenderedImage image(camera.width, camera.height);
    EventTimer upload, download;
    upload.begin();
    const DeviceFieldView device_view(view);
    DeviceBuffer<PixelRecord> out(image.pixels.size());
    upload.end();

    std::vector<double> kernel;
    const char* name = "";
    // One kernel instantiation per filter of the interpolator table
    visit_interpolator(kind, [&](auto interp) {
        using Interp = decltype(interp);
        name = Interp::name();
        const RaycastScene<float> scene =
            make_raycast_scene<Interp>(device_view.view(), camera.as<float>(), options.march.as<float>());
        kernel = launch_timed<Interp>(scene, out.get(), options.repetitions);
    });

    download.begin();
    out.download(image.pixels.data(), image.pixels.size());
    download.end();
    image.info = {{"renderer", "raycast"},
                  {"backend", "cuda"},
                  {"precision", "float"},
                  {"device", describe_device(options.device)},
                  {"interpolator", name},
                  {"repetitions", options.repetitions},
                  {"kernel_seconds", median_of(kernel)},
                  {"kernel_seconds_min", *std::min_element(kernel.begin(), kernel.end())},
                  {"kernel_seconds_all", kernel},
                  {"upload_seconds", upload.seconds()},
                  {"download_seconds", download.seconds()},
                  {"block", {kBlockX, kBlockY}}};
    return image;
}

}  // namespace sdf::cuda
