// CGAL peer: AABB_tree closest point (CGAL::AABB_tree over AABB_triangle_primitive, with
// accelerate_distance_queries()), the sign from CGAL::Side_of_triangle_mesh (ray casting
// on its own AABB tree), as a CGAL user computes a signed distance field. Double precision,
// Simple_cartesian kernel (no exact predicates are needed for a distance). Queries run in
// our parallel_for (the tree is read-only once built); the build is single-threaded.
//   The CGAL Project, "CGAL User and Reference Manual", 5.5: 3D Fast Intersection and
//   Distance Computation (AABB Tree); Polygon Mesh Processing, Side_of_triangle_mesh.
#include <chrono>
#include <list>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/version.h>

#include "core/parallel/parallel_for.h"
#include "experiments/peers/peer.h"

namespace sdf::peers {
namespace {

using K = CGAL::Simple_cartesian<double>;
using Point = K::Point_3;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
using Mesh = CGAL::Surface_mesh<Point>;

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

Mesh surface_mesh(const PreparedMesh& m) {
    Mesh sm;
    std::vector<Mesh::Vertex_index> v;
    for (const Vec3d& p : m.vertices()) v.push_back(sm.add_vertex(Point(p.x, p.y, p.z)));
    for (const Int3& t : m.triangles()) sm.add_face(v[size_t(t.x)], v[size_t(t.y)], v[size_t(t.z)]);
    return sm;
}

class CgalPeer final : public PeerAdapter {
public:
    std::string version() const override { return CGAL_VERSION_STR; }

    PeerResult run(const PeerInput& in) override {
        const PreparedMesh& mesh = *in.mesh;
        const std::vector<Vec3d>& points = *in.points;
        const int threads = in.threads;
        PeerResult r;
        r.sign = SignKind::Own;
        r.threads = threads;
        auto start = std::chrono::steady_clock::now();
        std::vector<Triangle> triangles;
        triangles.reserve(mesh.triangles().size());
        for (const Int3& t : mesh.triangles()) {
            const Vec3d a = mesh.vertices()[size_t(t.x)], b = mesh.vertices()[size_t(t.y)], c = mesh.vertices()[size_t(t.z)];
            triangles.emplace_back(Point(a.x, a.y, a.z), Point(b.x, b.y, b.z), Point(c.x, c.y, c.z));
        }
        Tree tree(triangles.begin(), triangles.end());
        tree.accelerate_distance_queries();
        const Mesh sm = surface_mesh(mesh);
        CGAL::Side_of_triangle_mesh<Mesh, K> side(sm);
        side(Point(points[0].x, points[0].y, points[0].z));  // builds its tree before the threads start
        r.build_seconds = seconds_since(start);

        r.distance.resize(points.size());
        std::vector<uint8_t> inside(points.size(), 0);
        start = std::chrono::steady_clock::now();
        parallel_for(int64_t(points.size()), 256, threads, [&](int64_t b, int64_t e) {
            for (int64_t i = b; i < e; ++i) {
                const Vec3d& p = points[size_t(i)];
                r.distance[size_t(i)] = std::sqrt(tree.squared_distance(Point(p.x, p.y, p.z)));
            }
        });
        const double distance_seconds = seconds_since(start);
        start = std::chrono::steady_clock::now();
        parallel_for(int64_t(points.size()), 256, threads, [&](int64_t b, int64_t e) {
            for (int64_t i = b; i < e; ++i) {
                const Vec3d& p = points[size_t(i)];
                inside[size_t(i)] = side(Point(p.x, p.y, p.z)) == CGAL::ON_BOUNDED_SIDE;
            }
        });
        const double sign_seconds = seconds_since(start);
        for (size_t i = 0; i < points.size(); ++i)
            if (inside[i]) r.distance[i] = -r.distance[i];
        r.query_seconds = distance_seconds + sign_seconds;
        r.details = {{"closest_point_seconds", distance_seconds},
                     {"sign_seconds", sign_seconds},
                     {"sign", "Side_of_triangle_mesh (ray casting)"},
                     {"precision", "double"}};
        return r;
    }
};

}  // namespace

std::unique_ptr<PeerAdapter> make_cgal_peer() { return std::make_unique<CgalPeer>(); }

}  // namespace sdf::peers
