// OpenVDB peer: tools::meshToSignedDistanceField on a FloatGrid whose voxels are the
// lattice's points (voxel size h, index (0,0,0) at the lattice origin), then the grid read
// at every lattice point (BoxSampler: exact at voxel centres, trilinear between them, for
// the BCC lattice's second grid). It is a narrow-band method: distances are computed within
// `band` voxels of the surface; elsewhere the grid holds the background value (+-band h)
// with the flood-filled sign. The experiment reports the band, the error inside it and the
// error outside it. Threads: TBB, limited with tbb::global_control.
// Band cases (OpenVdbBandPeer): tools::meshToLevelSet with the band's half-width in voxels
// on the same transform; its active voxels and their values are the row's.
//   Museth, "VDB: High-Resolution Sparse Volumes with Dynamic Topology", ACM TOG 2013.
#include <chrono>
#include <cmath>
#include <mutex>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/global_control.h>

#include "core/parallel/parallel_for.h"
#include "experiments/peers/peer.h"

namespace sdf::peers {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

class OpenVdbPeer final : public PeerAdapter {
public:
    explicit OpenVdbPeer(double band_voxels) : band_(band_voxels) {
        static std::once_flag once;
        std::call_once(once, [] { openvdb::initialize(); });
    }

    std::string version() const override { return openvdb::getLibraryVersionString(); }

    PeerResult run(const PeerInput& in) override {
        const PreparedMesh& mesh = *in.mesh;
        const std::vector<Vec3d>& points = *in.points;
        const int threads = in.threads;
        const Lattice& lattice = *in.lattice;
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        PeerResult r;
        r.sign = SignKind::Own;
        r.threads = threads;
        auto start = std::chrono::steady_clock::now();
        openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(lattice.spacing);
        xform->postTranslate(openvdb::Vec3d(lattice.origin.x, lattice.origin.y, lattice.origin.z));
        std::vector<openvdb::Vec3s> vertices;
        std::vector<openvdb::Vec3I> triangles;
        std::vector<openvdb::Vec4I> quads;
        for (const Vec3d& v : mesh.vertices()) vertices.emplace_back(float(v.x), float(v.y), float(v.z));
        for (const Int3& t : mesh.triangles()) triangles.emplace_back(unsigned(t.x), unsigned(t.y), unsigned(t.z));
        const float band = float(band_);
        openvdb::FloatGrid::Ptr grid =
            openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(*xform, vertices, triangles, quads, band, band);
        r.build_seconds = seconds_since(start);  // the whole narrow-band computation

        const float background = grid->background();
        r.distance.resize(points.size());
        r.in_band.resize(points.size());
        start = std::chrono::steady_clock::now();
        parallel_for(int64_t(points.size()), 4096, threads, [&](int64_t b, int64_t e) {
            // GridSampler keeps a pointer to the accessor: it must outlive the sampler (a
            // temporary here was a stack-use-after-scope under AddressSanitizer).
            const openvdb::FloatGrid::ConstAccessor accessor = grid->getConstAccessor();
            openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
                accessor, grid->transform());
            for (int64_t i = b; i < e; ++i) {
                const Vec3d& p = points[size_t(i)];
                const float v = sampler.wsSample(openvdb::Vec3d(p.x, p.y, p.z));
                r.distance[size_t(i)] = double(v);
                r.in_band[size_t(i)] = std::abs(v) < background * (1.0f - 1e-6f);
            }
        });
        r.query_seconds = seconds_since(start);
        r.details = {{"band_voxels", band_},
                     {"band_world", band_ * lattice.spacing},
                     {"background", background},
                     {"active_voxels", grid->activeVoxelCount()},
                     {"sign", "OpenVDB flood fill of the narrow band"},
                     {"precision", "float"},
                     {"timing", "build_seconds is the whole meshToSignedDistanceField; query_seconds reads the grid"}};
        return r;
    }

private:
    double band_;
};

/// The narrow band itself: meshToLevelSet on the lattice's transform, every active voxel out.
class OpenVdbBandPeer final : public PeerAdapter {
public:
    OpenVdbBandPeer() {
        static std::once_flag once;
        std::call_once(once, [] { openvdb::initialize(); });
    }

    std::string version() const override { return openvdb::getLibraryVersionString(); }

    PeerResult run(const PeerInput& in) override {
        const PreparedMesh& mesh = *in.mesh;
        const Lattice& lattice = *in.lattice;
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(in.threads));
        PeerResult r;
        r.sign = SignKind::Own;
        r.threads = in.threads;
        auto start = std::chrono::steady_clock::now();
        openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(lattice.spacing);
        xform->postTranslate(openvdb::Vec3d(lattice.origin.x, lattice.origin.y, lattice.origin.z));
        std::vector<openvdb::Vec3s> vertices;
        std::vector<openvdb::Vec3I> triangles;
        for (const Vec3d& v : mesh.vertices()) vertices.emplace_back(float(v.x), float(v.y), float(v.z));
        for (const Int3& t : mesh.triangles()) triangles.emplace_back(unsigned(t.x), unsigned(t.y), unsigned(t.z));
        r.build_seconds = seconds_since(start);  // the mesh in OpenVDB's arrays
        start = std::chrono::steady_clock::now();
        const float half_width = float(in.band_width / lattice.spacing);
        openvdb::FloatGrid::Ptr grid =
            openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, vertices, triangles, std::vector<openvdb::Vec4I>(), half_width);
        r.query_seconds = seconds_since(start);
        r.band_points.reserve(size_t(grid->activeVoxelCount()));
        r.distance.reserve(size_t(grid->activeVoxelCount()));
        for (auto it = grid->cbeginValueOn(); it; ++it) {
            if (!it.isVoxelValue()) continue;  // a level set has no active tiles; a voxel is a point
            const openvdb::Vec3d p = grid->indexToWorld(it.getCoord());
            r.band_points.push_back({p.x(), p.y(), p.z()});
            r.distance.push_back(double(*it));
        }
        r.details = {{"band_voxels", half_width},
                     {"background", grid->background()},
                     {"active_voxels", grid->activeVoxelCount()},
                     {"sign", "OpenVDB flood fill of the narrow band"},
                     {"precision", "float"},
                     {"timing", "build_seconds: the mesh copied into OpenVDB's float arrays; query_seconds: the whole "
                                "meshToLevelSet"}};
        return r;
    }
};

}  // namespace

std::unique_ptr<PeerAdapter> make_openvdb_band_peer() { return std::make_unique<OpenVdbBandPeer>(); }

std::unique_ptr<PeerAdapter> make_openvdb_peer(double band_voxels) { return std::make_unique<OpenVdbPeer>(band_voxels); }

}  // namespace sdf::peers
