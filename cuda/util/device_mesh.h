/// @file device_mesh.h
/// @brief A PreparedMesh's arrays on the GPU, as a MeshView with device pointers.
#pragma once

#include <memory>

#include "core/mesh/prepared_mesh.h"
#include "cuda/util/device_buffer.h"

namespace sdf::cuda {

template <typename T>
class DeviceMesh {
public:
    /// Uploads everything but the packed triangles, which the tuned kernel streams in chunks.
    explicit DeviceMesh(const MeshBuffers<T>& host, cudaStream_t stream = 0) : num_triangles_(int(host.triangles.size())) {
        vertices_.upload(host.vertices, stream);
        triangles_.upload(host.triangles, stream);
        face_normals_.upload(host.face_normals, stream);
        edge_normals_.upload(host.edge_normals, stream);
        vertex_normals_.upload(host.vertex_normals, stream);
        num_vertices_ = int(host.vertices.size());
        box_lo_ = host.box_lo;
        box_hi_ = host.box_hi;
    }

    /// Device bytes needed for `triangles` triangles and `vertices` vertices (without packed data).
    static size_t resident_bytes(size_t triangles, size_t vertices) {
        return triangles * (sizeof(Int3) + 4 * sizeof(Vec3<T>)) + vertices * 2 * sizeof(Vec3<T>);
    }

    MeshView<T> view(const PackedTriangle<T>* packed = nullptr) const {
        MeshView<T> v;
        v.vertices = vertices_.get();
        v.triangles = triangles_.get();
        v.face_normals = face_normals_.get();
        v.edge_normals = edge_normals_.get();
        v.vertex_normals = vertex_normals_.get();
        v.packed = packed;
        v.num_triangles = num_triangles_;
        v.num_vertices = num_vertices_;
        v.box_lo = box_lo_;
        v.box_hi = box_hi_;
        return v;
    }

private:
    DeviceBuffer<Vec3<T>> vertices_, face_normals_, edge_normals_, vertex_normals_;
    DeviceBuffer<Int3> triangles_;
    int num_triangles_ = 0, num_vertices_ = 0;
    Vec3<T> box_lo_{}, box_hi_{};
};

}  // namespace sdf::cuda
