/// @file device_mesh.h
/// @brief A PreparedMesh's arrays on the GPU, as a MeshView with device pointers.
#pragma once

#include <cstdlib>
#include <future>
#include <memory>

#include "core/mesh/prepared_mesh.h"
#include "cuda/device_buffer.h"

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

    /// The mesh uploaded while `work(mesh)` runs on stream 0 (the GPU BVH build): the vertices
    /// and triangles first, which the work may read, and the normals (most of the bytes)
    /// meanwhile, from another host thread on a stream of their own, since a copy from
    /// pageable memory holds the thread that makes it for as long as the bus takes.
    template <typename Work>
    static std::unique_ptr<DeviceMesh> upload_during(const MeshBuffers<T>& host, Work&& work) {
        std::unique_ptr<DeviceMesh> mesh(new DeviceMesh(host, kNormalsAllocatedOnly));
        int device = 0;
        CUDA_CHECK(cudaGetDevice(&device));
        CUDA_CHECK(cudaStreamSynchronize(0));  // the allocations, before another stream copies into them
        if (std::getenv("SDF_NORMALS_FIRST")) {  // measurement: the copies before the work, not beside it
            mesh->upload_normals(host, device);
            work(static_cast<const DeviceMesh&>(*mesh));
            return mesh;
        }
        std::future<void> normals = std::async(std::launch::async, [&] { mesh->upload_normals(host, device); });
        work(static_cast<const DeviceMesh&>(*mesh));  // should it throw, ~future waits for the copies
        normals.get();
        return mesh;
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
    enum NormalsAllocatedOnly { kNormalsAllocatedOnly };

    DeviceMesh(const MeshBuffers<T>& host, NormalsAllocatedOnly) : num_triangles_(int(host.triangles.size())) {
        vertices_.upload(host.vertices);
        triangles_.upload(host.triangles);
        face_normals_.allocate(host.face_normals.size());
        edge_normals_.allocate(host.edge_normals.size());
        vertex_normals_.allocate(host.vertex_normals.size());
        num_vertices_ = int(host.vertices.size());
        box_lo_ = host.box_lo;
        box_hi_ = host.box_hi;
    }

    /// The normals into their allocated arrays, on a stream of this thread's own; returns when
    /// they are on `device`.
    void upload_normals(const MeshBuffers<T>& host, int device) {
        CUDA_CHECK(cudaSetDevice(device));  // the current device is per host thread
        struct OwnStream {
            cudaStream_t stream{};
            ~OwnStream() {  // after its copies, also when one of them threw: the normals are freed on stream 0
                if (!stream) return;
                cudaStreamSynchronize(stream);
                cudaStreamDestroy(stream);
            }
        } own;
        CUDA_CHECK(cudaStreamCreateWithFlags(&own.stream, cudaStreamNonBlocking));
        face_normals_.upload(host.face_normals, own.stream);
        edge_normals_.upload(host.edge_normals, own.stream);
        vertex_normals_.upload(host.vertex_normals, own.stream);
        CUDA_CHECK(cudaStreamSynchronize(own.stream));
    }

    DeviceBuffer<Vec3<T>> vertices_, face_normals_, edge_normals_, vertex_normals_;
    DeviceBuffer<Int3> triangles_;
    int num_triangles_ = 0, num_vertices_ = 0;
    Vec3<T> box_lo_{}, box_hi_{};
};

}  // namespace sdf::cuda
