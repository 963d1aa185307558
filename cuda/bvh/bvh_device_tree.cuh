/// @file bvh_device_tree.cuh
/// @brief The CUDA BVH sampler's tree on its device, made once when the sampler is bound
/// (cuda/bvh/bvh_sampler.h): a tree built on the host and uploaded, or built on the device
/// (cuda/bvh/device_bvh_build.h), beside the double mesh, the winding moments of the winding
/// sign and the float search's certificate; and the certificate's steps, which a double
/// search (the reference) skips.
#pragma once

#include <memory>
#include <type_traits>

#include "core/bvh/triangle_bvh.h"
#include "core/mesh/prepared_mesh.h"
#include "core/sampling/certified_search.h"
#include "core/sampling/sampler_sign.h"
#include "cuda/bvh/bvh_sampler.h"
#include "cuda/sampling/certify_kernel.cuh"
#include "cuda/util/device_buffer.h"
#include "cuda/bvh/device_bvh_build.h"
#include "cuda/util/device_mesh.h"
#include "cuda/sampling/device_winding.h"

namespace sdf::cuda {

/// A BVH and the double mesh on the device, for one precision of the search, with the
/// winding moments when the sign (prepared for this mesh) is the winding number's.
template <typename T>
struct DeviceBvh {
    DeviceBuffer<BvhNode> nodes;
    DeviceBuffer<PackedTriangle<T>> packed;
    DeviceBuffer<int32_t> triangle_index;
    DeviceBuffer<int32_t> source_triangle;  ///< prepared -> mesh file face order (stored slabs)
    DeviceBuffer<PackedTriangle<double>> exact;  ///< a host tree's double constants (float search's certificate)
    DeviceBuffer<int32_t> slot_of;               ///< a host tree's slot of every triangle (the same)
    std::unique_ptr<DeviceMesh<double>> mesh;
    DeviceWinding winding;
    std::unique_ptr<DeviceCertifier> certifier;  ///< float only (certify_kernel.cuh)
    BvhView<T> view{};

    /// A tree built on the host: its nodes and triangle order and the double mesh go up once
    /// (the search, the certificate and the winding walk share them); the packed constants
    /// in tree order are made on the device from the mesh (the host's bits, and 29 MB less
    /// to copy at 100k triangles). The winding moments follow with add_winding().
    DeviceBvh(const TriangleBvh& bvh, const PreparedMesh& prepared) {
        mesh = std::make_unique<DeviceMesh<double>>(prepared.buffers<double>());
        nodes.upload(bvh.nodes);
        triangle_index.upload(bvh.triangle_index);
        source_triangle.upload(prepared.source_triangle());
        const int n = int(bvh.triangle_index.size());
        const MeshView<double> m = mesh->view();
        packed.allocate(size_t(n));
        if constexpr (std::is_same_v<T, float>) {
            exact.allocate(size_t(n));
            slot_of.allocate(size_t(n));
            pack_in_slot_order(m.vertices, m.triangles, triangle_index.get(), n, packed.get(), exact.get(), slot_of.get());
            view = {nodes.get(), packed.get(), triangle_index.get(), int(bvh.nodes.size()), n};
            certifier = std::make_unique<DeviceCertifier>(view, exact.get(), slot_of.get(), prepared.search_bound());
        } else {
            pack_in_slot_order(m.vertices, m.triangles, triangle_index.get(), n, nullptr, packed.get(), nullptr);
            view = bvh.view<double>().with_arrays(nodes.get(), packed.get(), triangle_index.get());  // and its margin
        }
    }

    /// The winding moments of `sign` (prepared for this mesh over `bvh`, this tree) beside it.
    void add_winding(const SamplerSign& sign, const TriangleBvh& bvh) {
        winding.upload_moments(sign, bvh, nodes.get(), triangle_index.get(), mesh->view());
    }

    /// The BVH built on the device (cuda/bvh/device_bvh_build.h), with its winding moments;
    /// `device_mesh` is the double mesh it was built from. Nothing is copied.
    DeviceBvh(std::unique_ptr<DeviceLbvh> built, std::unique_ptr<DeviceMesh<double>> device_mesh,
              const PreparedMesh& prepared, const SamplerSign& sign)
        : mesh(std::move(device_mesh)), lbvh(std::move(built)) {
        source_triangle.upload(prepared.source_triangle());
        winding.adopt(sign, lbvh->nodes.get(), lbvh->moments.get(), lbvh->triangle_index.get(), lbvh->num_nodes, mesh->view());
        view = lbvh->view<T>();
        if constexpr (std::is_same_v<T, float>)
            certifier = std::make_unique<DeviceCertifier>(view, lbvh->packed_double.get(), lbvh->slot_of.get(), lbvh->bound);
    }
    std::unique_ptr<DeviceLbvh> lbvh;  ///< owns the arrays of `view` when built on the device
};

/// The double search constants (PackedTriangle<double>) in the tree's slot order, whatever
/// its type and where it was built: what the double search and the certificate rank by.
template <typename T>
const PackedTriangle<double>* packed_double(const DeviceBvh<T>& dev) {
    if constexpr (std::is_same_v<T, double>) return dev.view.packed;
    else return dev.lbvh ? dev.lbvh->packed_double.get() : dev.exact.get();
}

/// The double search's view of the tree: its nodes and slots with the double constants, and
/// the double search's pruning margin (the float bound's), as certify_kernel.cuh's.
template <typename T>
BvhView<double> double_view(const DeviceBvh<T>& dev, const FloatSearchBound& bound) {
    if constexpr (std::is_same_v<T, double>) {
        return dev.view;
    } else {
        BvhView<double> v{dev.view.nodes, packed_double(dev), dev.view.triangle_index, dev.view.num_nodes, dev.view.num_triangles};
        v.margin = double_prune_margin(bound);
        return v;
    }
}

/// Certifies a float search's `nearest` (certify_kernel.cuh); double searches are the reference.
template <typename T, typename Piece>
void certify(const DeviceBvh<T>& dev, const Piece& piece, double point_coordinate, int* nearest) {
    if constexpr (std::is_same_v<T, float>) dev.certifier->certify(piece, point_coordinate, nearest);
}

/// The certificate fused into the warp kernel (float, and a bound that certifies at these
/// points); none (exact == nullptr: the separate pass certifies) otherwise.
template <typename T>
StreamedCertify streamed_certify(const DeviceBvh<T>& dev, BvhGpuKernel kernel, double point_coordinate) {
    if constexpr (std::is_same_v<T, float>)
        if (kernel == BvhGpuKernel::Warp) return dev.certifier->streamed(point_coordinate);
    return {};
}

/// The listed certificate's re-rank of a warp search's float winners (certify_kernel.cuh).
template <typename T, typename Piece>
void rerank_lists(const DeviceBvh<T>& dev, const Piece& piece, double point_coordinate, const NearLists& lists, int* nearest,
                  const NearestSideInputs& sides) {
    if constexpr (std::is_same_v<T, float>) dev.certifier->rerank_lists(piece, point_coordinate, lists, nearest, sides);
}

/// Zeroes the certifier's counters.
template <typename T>
void reset_certificate(const DeviceBvh<T>& dev) {
    if constexpr (std::is_same_v<T, float>) dev.certifier->reset();
}

/// Reads them into `counters`.
template <typename T>
void read_certificate(const DeviceBvh<T>& dev, CertificateCounters& counters) {
    if constexpr (std::is_same_v<T, float>) dev.certifier->read(counters);
}

}  // namespace sdf::cuda
