// NanoVDB peer (the OpenVDB project's GPU mesh-to-grid; tools/cuda/MeshToGrid.cuh), used as its
// own example ex_mesh_to_grid_cuda does: the mesh's float vertices and triangles on the device,
// MeshToGrid<ValueOnIndex> with the lattice's transform (voxel size h, voxel (0,0,0) at the
// lattice's origin) and the band's half-width in voxels, then getHandleAndUDF(): an index grid
// of the voxels within the band and a device array ("sidecar") of their distances in world
// units, UNSIGNED (the library's flood fill, SignedFloodFill.cuh, signs a level set's values,
// not this index grid's sidecar). Voxels the rasterisation marks but no triangle reaches
// within the band hold the band's width.
//
// Timings like the cuBQL peer's: build_seconds is the mesh's upload; query_seconds the
// CUDA-event time of the whole conversion (topology, pruning, distances) after one warm-up
// conversion; end_to_end adds the upload and the download of the grid and its sidecar. Built
// only with the CUDA backend and NanoVDB's headers (SDF_NANOVDB_DIR, cmake/Dependencies.cmake).
#include <nanovdb/NanoVDB.h>
#include <nanovdb/tools/cuda/MeshToGrid.cuh>

#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include <cuda_runtime.h>

#include "cuda/util/device_buffer.h"
#include "experiments/peers/peer.h"

namespace sdf::peers {
namespace {

void check(cudaError_t e, const char* what) {
    if (e != cudaSuccess) throw std::runtime_error(std::string("nanovdb peer: ") + what + ": " + cudaGetErrorString(e));
}

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// A device buffer freed on scope exit.
template <typename T>
struct DeviceArray {
    T* data = nullptr;
    explicit DeviceArray(size_t n) { check(cudaMalloc(reinterpret_cast<void**>(&data), n * sizeof(T) + 1), "cudaMalloc"); }
    ~DeviceArray() { cudaFree(data); }
    DeviceArray(const DeviceArray&) = delete;
    DeviceArray& operator=(const DeviceArray&) = delete;
};

using IndexGrid = nanovdb::NanoGrid<nanovdb::ValueOnIndex>;

class NanoVdbPeer final : public PeerAdapter {
public:
    std::string version() const override {
        return "NanoVDB " + std::to_string(NANOVDB_MAJOR_VERSION_NUMBER) + "." + std::to_string(NANOVDB_MINOR_VERSION_NUMBER) +
               "." + std::to_string(NANOVDB_PATCH_VERSION_NUMBER) + ", snapshot " + SDF_NANOVDB_COMMIT;
    }

    PeerResult run(const PeerInput& in) override {
        const PreparedMesh& mesh = *in.mesh;
        const Lattice& lattice = *in.lattice;
        PeerResult r;
        r.sign = SignKind::None;
        r.threads = 0;
        auto start = std::chrono::steady_clock::now();
        std::vector<nanovdb::Vec3f> vertices;
        std::vector<nanovdb::Vec3i> triangles;
        for (const Vec3d& v : mesh.vertices()) vertices.emplace_back(float(v.x), float(v.y), float(v.z));
        for (const Int3& t : mesh.triangles()) triangles.emplace_back(t.x, t.y, t.z);
        DeviceArray<nanovdb::Vec3f> d_vertices(vertices.size());
        DeviceArray<nanovdb::Vec3i> d_triangles(triangles.size());
        check(cudaMemcpy(d_vertices.data, vertices.data(), vertices.size() * sizeof(nanovdb::Vec3f), cudaMemcpyHostToDevice),
              "vertex upload");
        check(cudaMemcpy(d_triangles.data, triangles.data(), triangles.size() * sizeof(nanovdb::Vec3i), cudaMemcpyHostToDevice),
              "triangle upload");
        r.build_seconds = seconds_since(start);

        const nanovdb::Map map(lattice.spacing, nanovdb::Vec3d(lattice.origin.x, lattice.origin.y, lattice.origin.z));
        const float half_width = float(in.band_width / lattice.spacing);
        auto convert = [&] {
            nanovdb::tools::cuda::MeshToGrid<nanovdb::ValueOnIndex> converter(d_vertices.data, uint32_t(vertices.size()),
                                                                              d_triangles.data, uint32_t(triangles.size()), map);
            converter.setNarrowBandWidth(half_width);
            return converter.getHandleAndUDF();
        };
        { auto warm_up = convert(); }  // module load and the memory pool's first allocations
        check(cudaDeviceSynchronize(), "warm-up conversion");
        cuda::EventTimer conversion;  // its events are destroyed whatever throws (cuda/util/device_buffer.h)
        const auto wall = std::chrono::steady_clock::now();
        conversion.begin();
        auto [handle, sidecar] = convert();
        conversion.end();  // synchronises: a fault of the conversion throws here
        const double conversion_wall = seconds_since(wall);
        start = std::chrono::steady_clock::now();
        std::vector<char> grid_bytes(handle.bufferSize());
        std::vector<float> udf(sidecar.size() / sizeof(float));
        check(cudaMemcpy(grid_bytes.data(), handle.deviceData(), grid_bytes.size(), cudaMemcpyDeviceToHost), "grid download");
        check(cudaMemcpy(udf.data(), sidecar.deviceData(), udf.size() * sizeof(float), cudaMemcpyDeviceToHost), "sidecar download");
        const double download = seconds_since(start);
        r.query_seconds = conversion.seconds();
        r.end_to_end_seconds = r.build_seconds + conversion_wall + download;

        const IndexGrid* grid = reinterpret_cast<const IndexGrid*>(grid_bytes.data());
        const uint32_t leaves = grid->tree().nodeCount(0);
        const auto* leaf = grid->tree().getFirstLeaf();
        for (uint32_t l = 0; l < leaves; ++l, ++leaf)
            for (uint32_t v = 0; v < 512; ++v) {
                if (!leaf->isActive(v)) continue;
                const nanovdb::Coord ijk = leaf->offsetToGlobalCoord(v);
                const nanovdb::Vec3d p = grid->indexToWorld(nanovdb::Vec3d(ijk[0], ijk[1], ijk[2]));
                r.band_points.push_back({p[0], p[1], p[2]});
                r.distance.push_back(double(udf[size_t(leaf->getValue(v))]));
            }
        cudaDeviceProp prop{};
        int device = 0;
        cudaGetDevice(&device);
        cudaGetDeviceProperties(&prop, device);
        r.details = {{"sign", "none: MeshToGrid's distances are unsigned"},
                     {"precision", "float"},
                     {"band_voxels", half_width},
                     {"active_voxels", grid->activeVoxelCount()},
                     {"grid_bytes", grid_bytes.size()},
                     {"conversion_wall_seconds", conversion_wall},
                     {"download_seconds", download},
                     {"timing", "build_seconds: the mesh's upload; query_seconds: CUDA-event time of MeshToGrid::getHandleAndUDF "
                                "(after one warm-up conversion)"},
                     {"device", prop.name}};
        return r;
    }
};

}  // namespace

std::unique_ptr<PeerAdapter> make_nanovdb_peer(std::string& reason) {
    int devices = 0;
    if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
        cudaGetLastError();
        reason = "unavailable: no CUDA device";
        return nullptr;
    }
    return std::make_unique<NanoVdbPeer>();
}

}  // namespace sdf::peers
