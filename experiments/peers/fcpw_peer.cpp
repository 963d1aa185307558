// FCPW peer ("Fastest Closest Points in the West", Sawhney), used as its README recommends
// for speed: one flattened triangle object in a Scene<3>, AggregateType::Bvh_SurfaceArea
// built vectorised (an Enoki wide BVH, FCPW_SIMD_WIDTH lanes, set by
// experiments/peers/CMakeLists.txt from the build's ISA), then the batched
// Scene::findClosestPoints. Float precision. FCPW returns no sign unless the user supplies
// normals (Interaction::signedDistance with computeObjectNormals); its README documents only
// the closest point, so distances are unsigned, like Embree's.
//
// Threads: the batched findClosestPoints always starts std::thread::hardware_concurrency()
// threads (static split), with no way to ask for fewer. At that thread count it is called
// as is; at fewer threads the experiment runs the batch call's own loop body
// (Scene::findClosestPoint per point, the same aggregate query) in our parallel_for, so every
// library is compared at equal threads. `details` says which was used.
//   Sawhney, "FCPW: Fastest Closest Points in the West", github.com/rohan-sawhney/fcpw.
// The library is a source snapshot outside the repository (../shared/peers/fcpw, or
// SDF_PEERS_DIR); this file is built only when it is found.
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <fcpw/fcpw.h>

#include "core/parallel/parallel_for.h"
#include "experiments/peers/peer.h"

namespace sdf::peers {
namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

class FcpwPeer final : public PeerAdapter {
public:
    std::string version() const override { return std::string("snapshot ") + SDF_FCPW_COMMIT + " (Enoki, SIMD width " + std::to_string(FCPW_SIMD_WIDTH) + ")"; }

    PeerResult run(const PeerInput& in) override {
        const PreparedMesh& mesh = *in.mesh;
        const std::vector<Vec3d>& points = *in.points;
        const int threads = in.threads;
        PeerResult r;
        r.threads = threads;
        auto start = std::chrono::steady_clock::now();
        std::vector<fcpw::Vector3> positions(mesh.vertices().size());
        for (size_t i = 0; i < positions.size(); ++i) {
            const Vec3d& v = mesh.vertices()[i];
            positions[i] = fcpw::Vector3(float(v.x), float(v.y), float(v.z));
        }
        std::vector<fcpw::Vector3i> indices(mesh.triangles().size());
        for (size_t i = 0; i < indices.size(); ++i) {
            const Int3& t = mesh.triangles()[i];
            indices[i] = fcpw::Vector3i(t.x, t.y, t.z);
        }
        fcpw::Scene<3> scene;
        scene.setObjectCount(1);
        scene.setObjectVertices(positions, 0);
        scene.setObjectTriangles(indices, 0);
        scene.build(fcpw::AggregateType::Bvh_SurfaceArea, true);
        r.build_seconds = seconds_since(start);

        const int64_t n = int64_t(points.size());
        const int hardware = int(std::thread::hardware_concurrency());
        const bool batched = threads >= hardware;
        std::vector<fcpw::Interaction<3>> hits;
        start = std::chrono::steady_clock::now();
        if (batched) {
            Eigen::MatrixXf query(n, 3);
            for (int64_t i = 0; i < n; ++i) {
                const Vec3d& p = points[size_t(i)];
                query(i, 0) = float(p.x);
                query(i, 1) = float(p.y);
                query(i, 2) = float(p.z);
            }
            const Eigen::VectorXf radii = Eigen::VectorXf::Constant(n, fcpw::maxFloat);
            scene.findClosestPoints(query, radii, hits);
            r.threads = hardware;
        } else {
            hits.resize(size_t(n));
            parallel_for(n, 256, threads, [&](int64_t b, int64_t e) {
                for (int64_t i = b; i < e; ++i) {
                    const Vec3d& p = points[size_t(i)];
                    scene.findClosestPoint(fcpw::Vector3(float(p.x), float(p.y), float(p.z)), hits[size_t(i)]);
                }
            });
        }
        r.query_seconds = seconds_since(start);
        r.distance.resize(size_t(n));
        for (int64_t i = 0; i < n; ++i) r.distance[size_t(i)] = double(hits[size_t(i)].d);
        r.details = {{"sign", "none (FCPW returns the closest point; a sign needs user normals)"},
                     {"precision", "float"},
                     {"aggregate", "Bvh_SurfaceArea, vectorized (Enoki)"},
                     {"simd_width", FCPW_SIMD_WIDTH},
                     {"query_call", batched ? "Scene::findClosestPoints (batched; always all " + std::to_string(hardware) +
                                                  " hardware threads)"
                                            : "Scene::findClosestPoint per point in parallel_for (" + std::to_string(threads) +
                                                  " threads): the batch call's loop body, since the batch call cannot be "
                                                  "limited below " + std::to_string(hardware) + " threads"}};
        return r;
    }
};

}  // namespace

std::unique_ptr<PeerAdapter> make_fcpw_peer() { return std::make_unique<FcpwPeer>(); }

}  // namespace sdf::peers
