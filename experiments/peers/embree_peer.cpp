// Embree peer: rtcPointQuery over a triangle geometry (Embree's BVH and traversal, float),
// with the closest-point callback Embree's "closest_point" tutorial uses: Ericson's
// ClosestPtPointTriangle per candidate primitive, shrinking the query radius as it goes.
// Embree returns no sign (a user adds one); distances are unsigned. The build uses
// "threads=N"; the queries run in our parallel_for, one rtcPointQuery per point.
//   Wald et al., "Embree: A Kernel Framework for Efficient CPU Ray Tracing", ACM TOG 2014;
//   Ericson, "Real-Time Collision Detection", 2005, section 5.1.5.
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>

#include "core/parallel/parallel_for.h"
#include "experiments/peers/peer.h"

namespace sdf::peers {
namespace {

struct V3 {
    float x, y, z;
};
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

/// Ericson's ClosestPtPointTriangle (Real-Time Collision Detection, 5.1.5).
V3 closest_point_triangle(V3 p, V3 a, V3 b, V3 c) {
    const V3 ab = b - a, ac = c - a, ap = p - a;
    const float d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const V3 bp = p - b;
    const float d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const float vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
    const V3 cp = p - c;
    const float d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const float vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
    const float va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    const float denom = 1.0f / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

struct MeshData {
    const float* vertices;        ///< 3 per vertex
    const unsigned* indices;      ///< 3 per triangle
};

struct QueryResult {
    const MeshData* mesh;
    float distance = std::numeric_limits<float>::infinity();
};

bool closest_point_callback(RTCPointQueryFunctionArguments* args) {
    QueryResult* out = static_cast<QueryResult*>(args->userPtr);
    const unsigned* t = out->mesh->indices + 3 * size_t(args->primID);
    const float* v = out->mesh->vertices;
    const V3 p{args->query->x, args->query->y, args->query->z};
    const V3 a{v[3 * t[0]], v[3 * t[0] + 1], v[3 * t[0] + 2]}, b{v[3 * t[1]], v[3 * t[1] + 1], v[3 * t[1] + 2]},
             c{v[3 * t[2]], v[3 * t[2] + 1], v[3 * t[2] + 2]};
    const V3 q = closest_point_triangle(p, a, b, c) - p;
    const float d = std::sqrt(dot(q, q));
    if (d >= args->query->radius) return false;
    args->query->radius = d;  // shrink the search
    out->distance = d;
    return true;
}

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

class EmbreePeer final : public PeerAdapter {
public:
    std::string version() const override { return RTC_VERSION_STRING; }

    PeerResult run(const PeerInput& in) override {
        const PreparedMesh& mesh = *in.mesh;
        const std::vector<Vec3d>& points = *in.points;
        const int threads = in.threads;
        PeerResult r;
        r.threads = threads;
        auto start = std::chrono::steady_clock::now();
        const std::string config = "threads=" + std::to_string(threads);
        RTCDevice device = rtcNewDevice(config.c_str());
        if (!device) throw std::runtime_error("embree: rtcNewDevice(\"" + config + "\") failed");
        RTCScene scene = rtcNewScene(device);
        RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        float* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                3 * sizeof(float), mesh.vertices().size()));
        unsigned* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                      3 * sizeof(unsigned), mesh.triangles().size()));
        for (size_t i = 0; i < mesh.vertices().size(); ++i) {
            vb[3 * i] = float(mesh.vertices()[i].x);
            vb[3 * i + 1] = float(mesh.vertices()[i].y);
            vb[3 * i + 2] = float(mesh.vertices()[i].z);
        }
        for (size_t i = 0; i < mesh.triangles().size(); ++i)
            for (int k = 0; k < 3; ++k) ib[3 * i + size_t(k)] = unsigned(mesh.triangles()[i][k]);
        rtcCommitGeometry(geom);
        rtcAttachGeometry(scene, geom);
        rtcReleaseGeometry(geom);
        rtcCommitScene(scene);
        r.build_seconds = seconds_since(start);

        const MeshData data{vb, ib};
        r.distance.resize(points.size());
        start = std::chrono::steady_clock::now();
        parallel_for(int64_t(points.size()), 256, threads, [&](int64_t b, int64_t e) {
            for (int64_t i = b; i < e; ++i) {
                const Vec3d& p = points[size_t(i)];
                RTCPointQuery query;
                query.x = float(p.x);
                query.y = float(p.y);
                query.z = float(p.z);
                query.time = 0.f;
                query.radius = std::numeric_limits<float>::infinity();
                RTCPointQueryContext context;
                rtcInitPointQueryContext(&context);
                QueryResult result{&data};
                rtcPointQuery(scene, &query, &context, closest_point_callback, &result);
                r.distance[size_t(i)] = double(result.distance);
            }
        });
        r.query_seconds = seconds_since(start);
        rtcReleaseScene(scene);
        rtcReleaseDevice(device);
        r.details = {{"sign", "none (Embree returns the nearest primitive; signing is left to the user)"},
                     {"precision", "float"},
                     {"primitive_test", "Ericson ClosestPtPointTriangle (Embree closest_point tutorial)"}};
        return r;
    }
};

}  // namespace

std::unique_ptr<PeerAdapter> make_embree_peer() { return std::make_unique<EmbreePeer>(); }

}  // namespace sdf::peers
