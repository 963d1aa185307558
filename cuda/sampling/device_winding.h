/// @file device_winding.h
/// @brief A SamplerSign's winding BVH on the GPU: its nodes, per-node moments (double),
/// triangle order and table of sides from the closest triangle (surface_sides.h), next to a DeviceMesh<double> whose vertices and triangles it shares;
/// empty (pseudonormal mode) when the sign did not resolve to winding. Also the device's
/// counters of the certified sign (how each point's side was decided), read into a sampling's
/// counters (SlabRun::winding) and from there into its report.
#pragma once

#include "core/sampling/sampler_sign.h"
#include "cuda/util/device_buffer.h"
#include "cuda/sampling/winding_sign_kernel.cuh"

namespace sdf::cuda {

class DeviceWinding {
public:
    /// Uploads `sign`'s winding BVH when its mode is winding; `mesh` is the device copy of
    /// the same prepared mesh (double), whose arrays the winding view points into.
    void upload(const SamplerSign& sign, const MeshView<double>& mesh, cudaStream_t stream = 0) {
        view_ = {};
        const WindingSign* w = sign.winding_sign();
        if (w == nullptr) return;
        const WindingBvh& bvh = w->winding_bvh();
        nodes_.upload(bvh.bvh->nodes, stream);
        moments_.upload(bvh.moments, stream);
        triangle_index_.upload(bvh.bvh->triangle_index, stream);
        view_.view = {nodes_.get(), moments_.get(), triangle_index_.get(), mesh.vertices, mesh.triangles,
                      int(bvh.bvh->nodes.size())};
        finish(sign, mesh, stream);
    }

    /// As upload(), but the winding BVH's tree is `tree`, whose nodes and triangle order are
    /// already on the device (`nodes`, `triangle_index`): only the moments are copied.
    void upload_moments(const SamplerSign& sign, const TriangleBvh& tree, const BvhNode* nodes,
                        const int32_t* triangle_index, const MeshView<double>& mesh, cudaStream_t stream = 0) {
        view_ = {};
        const WindingSign* w = sign.winding_sign();
        if (w == nullptr) return;
        const WindingBvh& bvh = w->winding_bvh();
        if (bvh.bvh.get() != &tree) {  // moments over another tree: theirs go up whole
            upload(sign, mesh, stream);
            return;
        }
        moments_.upload(bvh.moments, stream);
        view_.view = {nodes, moments_.get(), triangle_index, mesh.vertices, mesh.triangles, int(tree.nodes.size())};
        finish(sign, mesh, stream);
    }

    /// Uses moments already on the device (the GPU build's, cuda/bvh/device_bvh_build.h) when
    /// `sign`'s mode is winding: nothing is copied; the arrays must outlive this view.
    void adopt(const SamplerSign& sign, const BvhNode* nodes, const WindingNode<double>* moments,
               const int32_t* triangle_index, int num_nodes, const MeshView<double>& mesh) {
        view_ = {};
        if (!sign.winding()) return;
        view_.view = {nodes, moments, triangle_index, mesh.vertices, mesh.triangles, num_nodes};
        finish(sign, mesh, 0);
    }

    const WindingSignView& view() const { return view_; }

    /// Zeroes the device's counters of the certified sign: before a sampling (its calls are
    /// serialised by the bound sampler, which owns this). Nothing in pseudonormal mode.
    void reset_counts(cudaStream_t stream = 0) const {
        if (view_.enabled() && counts_.get() != nullptr)
            CUDA_CHECK(cudaMemsetAsync(counts_.get(), 0, kWindingStages * sizeof(unsigned long long), stream));
    }

    /// Adds the points the device signed since reset_counts() to `run` (a sampling's
    /// counters, backend_sampler.h's SlabRun). Synchronises `stream`. Nothing in pseudonormal mode.
    void read_counts(SharedWindingCounts& run, cudaStream_t stream = 0) const {
        if (!view_.enabled() || counts_.get() == nullptr) return;
        unsigned long long c[kWindingStages] = {};
        counts_.download(c, kWindingStages, stream);
        CUDA_CHECK(cudaStreamSynchronize(stream));
        WindingSignCounts counts;
        for (int s = 0; s < kWindingStages; ++s) counts.add(WindingStage(s), int64_t(c[s]));
        run.add(counts);
    }

private:
    /// The certification, the rounding bounds' mesh figures and zeroed counters.
    void finish(const SamplerSign& sign, const MeshView<double>& mesh, cudaStream_t stream) {
        const WindingSignOptions o = SamplerSign::winding_options();
        view_.accuracy = o.accuracy;
        view_.certify = o.certify;
        view_.certification = o.certification;
        view_.view.num_triangles = mesh.num_triangles;
        view_.view.scale = sign.mesh_scale();
        const SurfaceSideView surface = sign.surface_view();
        if (surface.front_winding != nullptr) {  // the sides from the closest triangle
            surface_.upload(surface.front_winding, size_t(mesh.num_triangles), stream);
            stand_in_.upload(surface.stand_in, size_t(mesh.num_triangles), stream);
            view_.surface = {surface_.get(), stand_in_.get(), surface.min_distance};
        }
        if (counts_.get() == nullptr) counts_.allocate(kWindingStages);
        CUDA_CHECK(cudaMemsetAsync(counts_.get(), 0, kWindingStages * sizeof(unsigned long long), stream));
        view_.counts = counts_.get();
    }

    DeviceBuffer<BvhNode> nodes_;
    DeviceBuffer<WindingNode<double>> moments_;
    DeviceBuffer<int32_t> triangle_index_;
    DeviceBuffer<int8_t> surface_;  ///< SurfaceSides::front_winding
    DeviceBuffer<int32_t> stand_in_;  ///< SurfaceSides::stand_in
    DeviceBuffer<unsigned long long> counts_;  ///< kWindingStages: the current sampling's (scratch)
    WindingSignView view_;
};

}  // namespace sdf::cuda
