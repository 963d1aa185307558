// MeshSdf (harness/sampling/mesh_sdf.h), the bound object of issue 23: its queries and
// fields are the sampler's own, bit for bit, however many calls follow one build; closest
// points and barycentrics satisfy their definitions; unsigned distance is |d|; the winding
// number is occupancy; host arrays in and out equal the query. And the task monitor (core/parallel/task_monitor.h): a stop request
// ends parallel_for between chunks, and warnings go to the monitor instead of stderr.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <utility>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/parallel/parallel_for.h"
#include "core/parallel/task_monitor.h"
#include "harness/sampling/mesh_sdf.h"
#include "harness/sampling/sampler_table.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

std::shared_ptr<const PreparedMesh> torus() {
    static const auto mesh = std::make_shared<const PreparedMesh>(prepare_mesh(make_torus(1.0, 0.35, 48, 24)));
    return mesh;
}

std::vector<Vec3d> random_points(size_t n, double lo, double hi, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(lo, hi);
    std::vector<Vec3d> p(n);
    for (Vec3d& q : p) q = {u(rng), u(rng), u(rng)};
    return p;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

SamplerOptions cpu(const std::string& method, SignMode sign) {
    SamplerOptions o;
    o.backend = "cpu";
    o.method = method;
    o.sign = sign;
    o.progress = false;
    return o;
}

TEST(MeshSdf, QueriesEqualTheSamplersBitForBitCallAfterCall) {
    const auto points = random_points(3000, -1.6, 1.6, 3);
    for (const std::string method : {"bvh", "brute_force"})
        for (SignMode sign : {SignMode::Auto, SignMode::Pseudonormal, SignMode::Winding}) {
            const MeshSdf bound(torus(), cpu(method, sign));
            const std::vector<PointSample> ref = make_sampler(cpu(method, sign))->bind(share(torus()))->query(points);
            for (int call = 0; call < 3; ++call) {
                const std::vector<PointSample> got = bound.query(points);
                ASSERT_EQ(got.size(), ref.size());
                for (size_t i = 0; i < got.size(); ++i) {
                    ASSERT_TRUE(same_bits(got[i].distance, ref[i].distance)) << method << " point " << i;
                    ASSERT_TRUE(same_bits(got[i].gradient.x, ref[i].gradient.x) && same_bits(got[i].gradient.z, ref[i].gradient.z));
                    ASSERT_EQ(got[i].triangle, ref[i].triangle);
                }
            }
            EXPECT_EQ(bound.sign_mode(), sign == SignMode::Winding ? "winding" : "pseudonormal");
        }
}

TEST(MeshSdf, BoundObjectsOfOneMeshShareItsTree) {
    MeshPreparationOptions unchecked;
    unchecked.detect_intersections = false;  // so that the first bound object builds the tree
    const auto mesh = std::make_shared<const PreparedMesh>(prepare_mesh(make_torus(1.0, 0.35, 32, 16), unchecked));
    const MeshSdf first(mesh, cpu("bvh", SignMode::Pseudonormal));
    bool built = true;
    const auto tree = mesh->bvh(&built);
    EXPECT_FALSE(built);  // the first bound object built it
    const MeshSdf second(mesh, cpu("bvh", SignMode::Winding));
    const Lattice lattice = fit_lattice(LatticeType::CC, {8, 8, 8}, mesh->bounds(), 0.1);
    const SampledField field = second.sample(lattice);
    EXPECT_FALSE(field.sampler.details.at("bvh").at("built_by_bind").get<bool>());
    EXPECT_EQ(mesh->bvh(), tree);
}

TEST(MeshSdf, FieldsEqualTheSamplersBitForBit) {
    const Lattice lattice = fit_lattice(LatticeType::BCC, {9, 8, 7}, torus()->bounds(), 0.1);
    const MeshSdf bound(torus(), cpu("bvh", SignMode::Auto));
    const SampledField a = bound.sample(lattice);
    const SampledField b = make_sampler(cpu("bvh", SignMode::Auto))->bind(share(torus()))->sample(lattice);
    ASSERT_EQ(a.distance.size(), b.distance.size());
    for (size_t i = 0; i < a.distance.size(); ++i) {
        ASSERT_TRUE(same_bits(a.distance[i], b.distance[i])) << i;
        ASSERT_EQ(a.closest_triangle[i], b.closest_triangle[i]);
    }
}

TEST(MeshSdf, ClosestPointsAndBarycentricsMeetTheirDefinitions) {
    const MeshSdf bound(torus(), cpu("bvh", SignMode::Auto));
    const auto points = random_points(500, -1.6, 1.6, 5);
    const std::vector<PointSample> s = bound.query(points);
    const PreparedMesh& m = *torus();
    for (size_t i = 0; i < points.size(); ++i) {
        const ClosestPointOnMesh c = bound.closest_point(points[i], s[i].triangle);
        EXPECT_NEAR(length(points[i] - c.point), std::abs(s[i].distance), 1e-12);
        // The torus is not flipped and not welded: input face t is prepared triangle t.
        const Int3 f = m.triangles()[size_t(s[i].triangle)];
        const Vec3d from_weights = m.vertices()[size_t(f.x)] * c.barycentric.x + m.vertices()[size_t(f.y)] * c.barycentric.y +
                                   m.vertices()[size_t(f.z)] * c.barycentric.z;
        EXPECT_NEAR(length(from_weights - c.point), 0.0, 1e-12);
        EXPECT_NEAR(c.barycentric.x + c.barycentric.y + c.barycentric.z, 1.0, 1e-12);
    }
    EXPECT_THROW(bound.closest_point(points[0], -1), std::invalid_argument);
}

TEST(MeshSdf, UnsignedDistanceAndWindingNumbers) {
    const auto points = random_points(800, -1.6, 1.6, 7);
    const MeshSdf signed_sdf(torus(), cpu("bvh", SignMode::Auto));
    const MeshSdf unsigned_sdf(torus(), cpu("bvh", SignMode::Auto), true);
    EXPECT_EQ(unsigned_sdf.sign_mode(), "none");
    const auto s = signed_sdf.query(points), u = unsigned_sdf.query(points);
    const std::vector<double> w = signed_sdf.winding_numbers(points, 0);
    for (size_t i = 0; i < points.size(); ++i) {
        EXPECT_TRUE(same_bits(u[i].distance, std::abs(s[i].distance)));
        if (s[i].distance < -1e-3) {
            EXPECT_NEAR(w[i], 1.0, 0.05);
        } else if (s[i].distance > 1e-3) {
            EXPECT_NEAR(w[i], 0.0, 0.05);
        }
    }
}

// Host arrays in and out (core/sampling/host_query.h: the Python module's path): float32
// rows and strided float64 rows give query()'s numbers bit for bit, signed and unsigned,
// with or without the distance column; closest_points() is closest_point() per row.
TEST(MeshSdf, HostArraysEqualTheQueryBitForBit) {
    const auto points = random_points(2500, -1.6, 1.6, 9);
    const size_t n = points.size();
    std::vector<float> rows32(3 * n);
    std::vector<double> padded64(5 * n, 99.0);
    std::vector<Vec3d> as_float(n);
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            rows32[3 * i + k] = float(points[i][k]);
            as_float[i][k] = double(rows32[3 * i + k]);
            padded64[5 * i + 2 * k] = points[i][k];  // every other column of an N x 5 array
        }
    // The pseudonormal (auto on the torus) and the winding sign (the nearest triangles' side,
    // the packets' certified search): the CPU BVH reads the arrays in place for both.
    const std::pair<SignMode, bool> modes[] = {{SignMode::Auto, false}, {SignMode::Auto, true}, {SignMode::Winding, false}};
    for (const auto& [sign, unsigned_distance] : modes) {
        const MeshSdf bound(torus(), cpu("bvh", sign), unsigned_distance);
        const std::vector<PointSample> ref = bound.query(points), ref_float = bound.query(as_float);
        struct Case { HostPoints points; const std::vector<PointSample>* truth; };
        for (const Case& c : {Case{{rows32.data(), true, int64_t(n), 3, 1}, &ref_float}, Case{{padded64.data(), false, int64_t(n), 5, 2}, &ref}}) {
            std::vector<double> d(n), g(3 * n), g_only(3 * n);
            std::vector<int32_t> t(n);
            bound.query_host(c.points, {d.data(), g.data(), t.data()});
            bound.query_host(c.points, {nullptr, g_only.data(), nullptr});
            for (size_t i = 0; i < n; ++i) {
                const PointSample& e = (*c.truth)[i];
                ASSERT_TRUE(same_bits(d[i], e.distance)) << "point " << i << (unsigned_distance ? " unsigned" : "");
                for (int k = 0; k < 3; ++k) {
                    ASSERT_TRUE(same_bits(g[3 * i + k], e.gradient[k])) << "point " << i;
                    ASSERT_TRUE(same_bits(g_only[3 * i + k], e.gradient[k])) << "point " << i;
                }
                ASSERT_EQ(t[i], e.triangle);
            }
            std::vector<double> cp(3 * n), bary(3 * n);
            bound.closest_points(c.points, t.data(), cp.data(), bary.data(), 0);
            for (size_t i = 0; i < n; i += 97) {
                const ClosestPointOnMesh e = bound.closest_point(c.points[int64_t(i)], t[i]);
                ASSERT_TRUE(same_bits(cp[3 * i + 1], e.point.y) && same_bits(bary[3 * i + 2], e.barycentric.z)) << i;
            }
        }
    }
    std::vector<double> bad(9, 0.5), d(3);
    bad[7] = std::nan("");
    const MeshSdf bound(torus(), cpu("bvh", SignMode::Auto));
    try {
        bound.query_host({bad.data(), false, 3, 3, 1}, {d.data(), nullptr, nullptr});
        ADD_FAILURE() << "a NaN point was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("row 2 is not three finite numbers"), std::string::npos) << e.what();
    }
}

TEST(MeshSdf, ALongListNamesItsFirstBadPointOnAnyThreadCount) {
    // Bad rows in different chunks of the threaded range check: the first is named.
    std::vector<Vec3d> points(300000, Vec3d(0.1, 0.2, 0.3));
    points[250000].y = std::nan("");
    points[140000].z = 1e300;
    points[140001].x = INFINITY;
    for (int threads : {1, 2, 7}) {
        SamplerOptions o = cpu("bvh", SignMode::Auto);
        o.threads = threads;
        const MeshSdf bound(torus(), o);
        try {
            bound.query(points);
            ADD_FAILURE() << "bad points were accepted on " << threads << " threads";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("query points: row 140000 has a coordinate of magnitude 1e+300"),
                      std::string::npos)
                << e.what();
        }
    }
}

TEST(TaskMonitor, AStopRequestEndsParallelForBetweenChunks) {
    TaskMonitor monitor;
    ScopedTaskMonitor scope(&monitor);
    std::atomic<int64_t> chunks{0};
    EXPECT_THROW(parallel_for(1000, 10, 2,
                              [&](int64_t, int64_t) {
                                  if (++chunks == 5) monitor.request_stop();
                              }),
                 TaskStopped);
    EXPECT_LT(chunks.load(), 100);  // stopped long before the 100 chunks
}

TEST(TaskMonitor, WarningsGoToTheMonitor) {
    TaskMonitor monitor;
    {
        ScopedTaskMonitor scope(&monitor);
        report_warning("first");
        report_warning("second");
    }
    EXPECT_EQ(monitor.take_warnings(), (std::vector<std::string>{"first", "second"}));
    EXPECT_TRUE(monitor.take_warnings().empty());
    EXPECT_EQ(current_task_monitor(), nullptr);
}

}  // namespace
}  // namespace sdf
