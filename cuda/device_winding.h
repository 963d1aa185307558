/// @file device_winding.h
/// @brief A SamplerSign's winding BVH on the GPU: its nodes, per-node moments (double) and
/// triangle order, next to a DeviceMesh<double> whose vertices and triangles it shares;
/// empty (pseudonormal mode) when the sign did not resolve to winding.
#pragma once

#include "core/sampling/sampler_sign.h"
#include "cuda/device_buffer.h"
#include "cuda/winding_sign_kernel.cuh"

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
        view_.accuracy = SamplerSign::winding_options().accuracy;
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
        view_.accuracy = SamplerSign::winding_options().accuracy;
    }

    /// Uses moments already on the device (the GPU build's, cuda/device_bvh_build.h) when
    /// `sign`'s mode is winding: nothing is copied; the arrays must outlive this view.
    void adopt(const SamplerSign& sign, const BvhNode* nodes, const WindingNode<double>* moments,
               const int32_t* triangle_index, int num_nodes, const MeshView<double>& mesh) {
        view_ = {};
        if (!sign.winding()) return;
        view_.view = {nodes, moments, triangle_index, mesh.vertices, mesh.triangles, num_nodes};
        view_.accuracy = SamplerSign::winding_options().accuracy;
    }

    const WindingSignView& view() const { return view_; }

private:
    DeviceBuffer<BvhNode> nodes_;
    DeviceBuffer<WindingNode<double>> moments_;
    DeviceBuffer<int32_t> triangle_index_;
    WindingSignView view_;
};

}  // namespace sdf::cuda
