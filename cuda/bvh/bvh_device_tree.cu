// The CUDA BVH sampler's binding: the tree built on the device (bvh_build "device" or
// "auto", with either sign) or on the host and uploaded, with the winding sign's
// moments and the float search's certificate beside it (bvh_device_tree.cuh).
#include <cstdlib>
#include <cstring>
#include <future>
#include <string>

#include "core/parallel/task_monitor.h"
#include "cuda/bvh/bvh_bound_sampler.cuh"
#include "cuda/util/cuda_check.h"

namespace sdf::cuda {

BoundCudaBvh::BoundCudaBvh(std::shared_ptr<const PreparedMesh> mesh, const SamplerOptions& options, BvhGpuKernel kernel)
    : BackendSampler(std::move(mesh), options, "cuda", "bvh", kernel_name(kCudaBvhKernels, kernel)), kernel_(kernel) {
    const DeviceGuard on_device(options.device);
    with_precision(options.precision, [&](auto zero) {
        using T = decltype(zero);
        if (!build_on_device<T>()) upload_host_tree<T>();
    });
    if (kernel_ == BvhGpuKernel::Candidates) candidate_stats_.allocate(4);
    if (kernel_ == BvhGpuKernel::Warp) warp_queue_.allocate(1);
}

namespace {

/// The device tree's build options: the defaults, or for measurement SDF_GPU_BVH_MAX_LEAF
/// (1 to 16) and SDF_GPU_PLOC_RADIUS (1 to 64). The field does not depend on the tree; its
/// speed does.
GpuBvhBuildOptions device_build_options() {
    static const GpuBvhBuildOptions options = [] {
        GpuBvhBuildOptions o;
        const auto knob = [](const char* name, int lo, int hi, int fallback) {
            const char* e = std::getenv(name);
            const int v = e ? std::atoi(e) : 0;
            return v >= lo && v <= hi ? v : fallback;
        };
        o.max_leaf = knob("SDF_GPU_BVH_MAX_LEAF", 1, 16, o.max_leaf);
        o.ploc_radius = knob("SDF_GPU_PLOC_RADIUS", 1, 64, o.ploc_radius);
        return o;
    }();
    return options;
}

}  // namespace

unsigned long long* BoundCudaBvh::warp_queue() const {
    static const bool off = [] {
        const char* e = std::getenv("SDF_WARP_QUEUE");
        return e != nullptr && std::strcmp(e, "off") == 0;
    }();
    return off ? nullptr : warp_queue_.get();
}

/// A tree built on the host (the mesh's own, PreparedMesh::bvh()) goes up with the double
/// mesh, while the winding moments are made on the host's threads over that tree: neither
/// waits for the other.
template <typename T>
void BoundCudaBvh::upload_host_tree() {
    const std::shared_ptr<const TriangleBvh> bvh = mesh().bvh(&built_);
    // The caller's task monitor goes along: the sign's "auto" warning reaches Python's
    // SdfWarning, and a stop request stops the moments.
    std::future<void> sign = std::async(std::launch::async, [&, monitor = current_task_monitor()] {
        const ScopedTaskMonitor scope(monitor);
        sign_.prepare(mesh());
    });
    std::unique_ptr<DeviceBvh<T>> dev;
    try {
        dev = std::make_unique<DeviceBvh<T>>(*bvh, mesh());
    } catch (...) {
        sign.wait();
        throw;
    }
    sign.get();
    dev->add_winding(sign_, *bvh);
    if constexpr (std::is_same_v<T, float>) tree_float_ = std::move(dev);
    else tree_double_ = std::move(dev);
    // Null until build_on_device() said why it did not build (nlohmann's value() throws on null).
    const std::string skipped =
        bvh_stats_.is_object() ? bvh_stats_.value("device_build_skipped", std::string()) : std::string();
    bvh_stats_ = bvh->stats.to_json();
    bvh_stats_["built_on"] = "host";
    if (!skipped.empty()) bvh_stats_["device_build_skipped"] = skipped;
}

/// The BVH built on the device (bvh_build "device" or "auto": the field does not depend on
/// the tree, docs/bvh.md, "Build on the GPU", and docs/winding.md, the certified sign); false where
/// the host builds it, with the reason in the provenance's bvh.device_build_skipped (also
/// when the device tree is too deep).
template <typename T>
bool BoundCudaBvh::build_on_device() {
    if (options_.bvh_build == BvhBuildSite::Host) return false;
    // Auto builds on the device for either sign: the pseudonormal sign and the certified
    // winding sign (kernels/winding/certified_winding.h) do not depend on the tree.
    // The whole mesh first: its normals' copy from pageable memory beside the build (another
    // host thread, another stream) made the build 1.5-2 ms slower and the first call no
    // faster (H100, docs/gpu-notes.md).
    auto dmesh = std::make_unique<DeviceMesh<double>>(mesh().buffers<double>());
    const GpuBvhBuildOptions build = device_build_options();
    std::unique_ptr<DeviceLbvh> lbvh = build_lbvh_on_device(mesh(), dmesh->view().vertices, dmesh->view().triangles, build);
    if (!lbvh || !lbvh->within_depth) {
        bvh_stats_["device_build_skipped"] = lbvh ? "the device tree is deeper than kBvhMaxDepth = " + std::to_string(kBvhMaxDepth) +
                                                        " (depth " + std::to_string(lbvh->stats.depth) + ")"
                                                  : "the mesh fits one leaf";
        return false;
    }
    sign_.prepare_mode(mesh());
    bvh_stats_ = lbvh->stats.to_json();
    bvh_stats_["built_on"] = "device";
    bvh_stats_["builder"] = gpu_bvh_builder_name(build.builder);
    bvh_stats_["max_leaf"] = build.max_leaf;
    bvh_stats_["ploc_radius"] = build.ploc_radius;
    bvh_stats_["device_seconds"] = lbvh->device_seconds;
    sign_.set_external_moments(lbvh->device_seconds, "device");
    auto dev = std::make_unique<DeviceBvh<T>>(std::move(lbvh), std::move(dmesh), mesh(), sign_);
    if constexpr (std::is_same_v<T, float>) tree_float_ = std::move(dev);
    else tree_double_ = std::move(dev);
    built_ = true;
    return true;
}

}  // namespace sdf::cuda
