// The certified float search (kernels/distance/search_certificate.h) as a property: on the
// adversarial cases (core/sampling/adversarial_cases.h: a cube's face diagonals, a CAD-like
// fan plate, slivers, meshes 1e3 and 1e5 from the origin, nested and overlapping parts at
// tiny gaps) every CPU float search (brute force; BVH brick packets, seeded, unseeded; point
// queries and lattices) returns bit for bit the distance, gradient and triangle of the double
// brute force. Also checks the error bound itself pair by pair, and that double runs did not
// change (the double BVH equals the double brute force on these points).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/bvh/triangle_bvh.h"
#include "core/sampling/adversarial_cases.h"
#include "core/sampling/certified_search.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "kernels/bvh/streamed_certificate.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

SamplerOptions options(Precision precision, const std::string& kernel) {
    SamplerOptions o;
    o.precision = precision;
    o.kernel = kernel;
    o.progress = false;
    return o;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// Number of points where `got` differs from `want` in any bit of distance or gradient, or in
/// the triangle; prints the first few.
int64_t differences(const std::string& what, const std::vector<Vec3d>& points, const std::vector<PointSample>& got,
                    const std::vector<PointSample>& want) {
    int64_t bad = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        const PointSample &g = got[i], &w = want[i];
        const bool same = g.triangle == w.triangle && same_bits(g.distance, w.distance) && same_bits(g.gradient.x, w.gradient.x) &&
                          same_bits(g.gradient.y, w.gradient.y) && same_bits(g.gradient.z, w.gradient.z);
        if (!same && bad++ < 3)
            std::printf("  %s: point %zu (%.17g %.17g %.17g): triangle %d d %.17g, double brute force %d d %.17g\n", what.c_str(),
                        i, points[i].x, points[i].y, points[i].z, g.triangle, g.distance, w.triangle, w.distance);
    }
    return bad;
}

std::vector<PointSample> query(const std::string& method, Precision precision, const std::string& kernel,
                               const PreparedMesh& mesh, const std::vector<Vec3d>& points, SamplingTimings* timings = nullptr) {
    const SamplerOptions o = options(precision, kernel);
    auto sampler = method == "bvh" ? make_cpu_bvh_sampler(o) : make_cpu_brute_force_sampler(o);
    return sampler->bind(share(mesh))->query(points, timings);
}

// A long point list's largest |coordinate| (the bound of every certified query) is taken in
// chunks on several threads: the same value as one pass, wherever the largest point is, with
// infinities kept and NaN coordinates passed over as std::max passes over them.
TEST(CertifiedSearch, LargestCoordinateOfAPointListAtEveryThreadCount) {
    std::vector<Vec3d> points(700000);
    for (size_t i = 0; i < points.size(); ++i)
        points[i] = {std::sin(double(i)), -std::cos(0.5 * double(i)), 0.25 * std::sin(0.3 * double(i))};
    const auto one_pass = [](const std::vector<Vec3d>& p) {
        double m = 0;
        for (const Vec3d& q : p) m = std::max(m, largest_coordinate(q));
        return m;
    };
    for (const size_t at : {size_t(0), size_t(262143), size_t(262144), size_t(699999)}) {
        std::vector<Vec3d> p = points;
        p[at].y = -7.5;
        p[(at + 1) % p.size()].x = std::numeric_limits<double>::quiet_NaN();
        for (const int threads : {1, 2, 3, 0}) EXPECT_EQ(largest_coordinate(p, threads), 7.5) << at << " " << threads;
        EXPECT_EQ(one_pass(p), 7.5);
        p[at].z = std::numeric_limits<double>::infinity();
        EXPECT_EQ(largest_coordinate(p, 2), std::numeric_limits<double>::infinity());
    }
    EXPECT_EQ(largest_coordinate(std::vector<Vec3d>{}, 2), 0.0);
}

TEST(CertifiedSearch, FloatEqualsDoubleBruteForceOnAdversarialPoints) {
    for (const AdversarialCase& c : adversarial_cases(2026, 1500)) {
        const PreparedMesh mesh = prepare_mesh(c.mesh);
        const std::vector<PointSample> want = query("brute_force", Precision::Double, "vectorized", mesh, c.points);
        struct Run { const char* method; const char* kernel; };
        for (const Run r : {Run{"brute_force", "vectorized"}, Run{"bvh", "brick"}, Run{"bvh", "seeded"}, Run{"bvh", "unseeded"}}) {
            SamplingTimings t;
            const std::vector<PointSample> got = query(r.method, Precision::Float, r.kernel, mesh, c.points, &t);
            const std::string what = c.mesh.name + " float " + r.method + "/" + r.kernel;
            std::printf("%-45s %6zu points: re-ranked in double %lld, full double search %lld\n", what.c_str(), c.points.size(),
                        (long long)t.reranked_points, (long long)t.full_double_points);
            EXPECT_EQ(differences(what, c.points, got, want), 0) << what;
            EXPECT_EQ(t.certified_points, int64_t(c.points.size())) << what;
        }
        const std::vector<PointSample> bvh_double = query("bvh", Precision::Double, "brick", mesh, c.points);
        EXPECT_EQ(differences(c.mesh.name + " double bvh", c.points, bvh_double, want), 0);
    }
}

/// The samplers on the needle fans (bvh_test_meshes.h), 1e7 from the origin and near it:
/// double BVH (every kernel) and certified float equal the double brute force.
TEST(CertifiedSearch, NeedleFansEqualDoubleBruteForce) {
    for (const Vec3d center : {Vec3d{1e7, -3e6, 5e6}, Vec3d{0.5, 0.25, -0.125}}) {
        const test::NeedleFan fan = test::make_needle_fan(center);
        const PreparedMesh mesh = test::prepare_needle_fan(fan);
        const std::vector<PointSample> want = query("brute_force", Precision::Double, "vectorized", mesh, fan.points);
        for (const char* kernel : {"brick", "seeded", "unseeded"}) {
            for (Precision p : {Precision::Double, Precision::Float}) {
                const std::string what = std::string("needle_fan ") + (p == Precision::Double ? "double" : "float") + " bvh/" + kernel;
                EXPECT_EQ(differences(what, fan.points, query("bvh", p, kernel, mesh, fan.points), want), 0) << what;
            }
        }
    }
}

/// The bound of search_certificate.h holds pair by pair: Q_d - E <= Q_f <= Q_d + E (+ the
/// sliver excess of float-only slivers) for every point and triangle of the cases.
TEST(CertifiedSearch, ErrorBoundHoldsForEveryPair) {
    for (const AdversarialCase& c : adversarial_cases(7, 300)) {
        const PreparedMesh mesh = prepare_mesh(c.mesh);
        const FloatSearchBound b = float_search_bound(mesh);
        ASSERT_TRUE(b.usable) << c.mesh.name;
        const auto& pf = mesh.buffers<float>().packed;
        const auto& pd = mesh.buffers<double>().packed;
        double worst = 0;
        for (const Vec3d& p : c.points) {
            const double d0 = std::sqrt(3.0) * 0x1p-24 * (b.coordinate + largest_coordinate(p));
            for (size_t t = 0; t < pf.size(); ++t) {
                const double qd = squared_distance(pd[t], p.x, p.y, p.z);
                const double qf = squared_distance(pf[t], float(p.x), float(p.y), float(p.z));
                const double x = sliver_excess(pf[t]);  // float-only sliver: Q_f over-estimates by up to x
                const double m = std::sqrt(qd) + b.two_l;  // M for this pair, as the bound's comment bounds it
                const double e = (b.rho * m + 2.0 * d0) * m + d0 * d0;
                worst = std::max({worst, (qf - x - qd) / e, (qd - qf) / e});
            }
        }
        std::printf("%-32s largest error / E: %.3g\n", c.mesh.name.c_str(), worst);
        EXPECT_LE(worst, 1.0) << c.mesh.name;
    }
}


/// A float packet of the K points point_of(k), nothing found yet.
template <int K, typename PointOf>
BvhPacket<float, K> unsearched_packet(const PointOf& point_of) {
    BvhPacket<float, K> pk;
    for (int k = 0; k < K; ++k) {
        const Vec3f p(point_of(k));
        pk.x[k] = p.x; pk.y[k] = p.y; pk.z[k] = p.z;
        pk.best_q[k] = pk.radius[k] = std::numeric_limits<float>::infinity();
        pk.best_slot[k] = pk.best_triangle[k] = -1;
    }
    return pk;
}

/// The certificate fused into a packet search (kernels/bvh/streamed_certificate.h, the GPU
/// warp kernel's form) on the CPU: packets of 4 consecutive case points, and
/// the same points 4 copies to a packet (every lane ties with the others). Every lane's
/// triangle is the double brute force's; the fan plate's centre vertex (dozens of triangles
/// tied exactly) overflows the two deferred candidates, so the streamed double re-rank runs.
/// `seeded`: each lane first takes the nearest triangle of its own descent (seed_by_descent,
/// the GPU point lists' seeds), which the walk must still offer as a candidate.
void check_streamed_packets(bool seeded) {
    constexpr int K = 4;
    int64_t streamed_lanes = 0, single_lanes = 0;
    for (const AdversarialCase& c : adversarial_cases(2026, 1500)) {
        const PreparedMesh mesh = prepare_mesh(c.mesh);
        const TriangleBvh bvh = build_triangle_bvh(mesh);
        const BvhView<float> view = bvh.view<float>();
        const std::vector<PointSample> want = query("brute_force", Precision::Double, "vectorized", mesh, c.points);
        double coordinate = 0;
        for (const Vec3d& p : c.points) coordinate = std::max(coordinate, largest_coordinate(p));
        const SearchSlack<float> slack = make_search_slack(float_search_bound(mesh), coordinate);
        ASSERT_TRUE(slack.certify) << c.mesh.name;
        int64_t bad = 0;
        for (const int stride : {1, 0}) {  // 1: 4 consecutive points; 0: one point in every lane
            for (size_t first = 0; first < c.points.size(); first += K) {
                size_t index[K];
                for (int k = 0; k < K; ++k) index[k] = std::min(first + size_t(k * stride), c.points.size() - 1);
                const auto point_of = [&](int k) { return c.points[index[k]]; };
                BvhPacket<float, K> pk = unsearched_packet<K>(point_of);
                StreamedCertifiedNear<float, K, decltype(point_of)> near(slack, bvh.packed_double.data(), point_of);
                if (seeded) seed_by_descent(view, pk, near);
                NoBvhStats none;
                closest_triangles_packet(view, pk, none, near);
                for (int k = 0; k < K; ++k) {
                    streamed_lanes += near.spill.exact_triangle[k] >= 0;
                    bool reranked = false;
                    const int got = mesh.source_triangle()[size_t(near.finish(view, k, pk, reranked))];
                    single_lanes += !reranked;
                    if (got != want[index[k]].triangle && bad++ < 3)
                        std::printf("  %s point %zu: streamed %d, double brute force %d\n", c.mesh.name.c_str(), index[k], got,
                                    want[index[k]].triangle);
                }
            }
        }
        EXPECT_EQ(bad, 0) << c.mesh.name;
    }
    std::printf("streamed packets%s: %lld lanes streamed, %lld certified without double work\n", seeded ? ", seeded" : "",
                (long long)streamed_lanes, (long long)single_lanes);
    EXPECT_GT(streamed_lanes, 0);
    EXPECT_GT(single_lanes, 0);
}

TEST(CertifiedSearch, StreamedPacketEqualsDoubleBruteForce) { check_streamed_packets(false); }

/// The listed form (NearListAppend, the GPU point lists'): the same packets, each lane's
/// candidates written to its list and re-ranked after the search (rerank_near_list). Every
/// lane's triangle is the double brute force's; a list that overflows (the fan plate's centre
/// vertex) takes the double BVH search; every triangle the double evaluation puts no farther
/// than the float winner is among the live candidates nearest_side() receives. With lists of
/// two entries (`slots`) nearly every lane fills its list: the entries a full list drops
/// (beyond the radius of their time, or its largest, remembered) must never lose a candidate
/// of a lane that does not overflow. `seeded` as check_streamed_packets().
void check_listed_packets(int slots, bool seeded = false) {
    constexpr int K = 4;
    int64_t listed_lanes = 0, single_lanes = 0, overflows = 0;
    for (const AdversarialCase& c : adversarial_cases(2026, 1500)) {
        const PreparedMesh mesh = prepare_mesh(c.mesh);
        const TriangleBvh bvh = build_triangle_bvh(mesh);
        const BvhView<float> view = bvh.view<float>();
        const BvhView<double> exact = bvh.view<double>();
        const std::vector<PointSample> want = query("brute_force", Precision::Double, "vectorized", mesh, c.points);
        double coordinate = 0;
        for (const Vec3d& p : c.points) coordinate = std::max(coordinate, largest_coordinate(p));
        const SearchSlack<float> slack = make_search_slack(float_search_bound(mesh), coordinate);
        ASSERT_TRUE(slack.certify) << c.mesh.name;
        std::vector<int32_t> list_slots(size_t(K * slots));
        std::vector<float> qs(size_t(K * slots));
        int32_t counts[K];
        float best[K];
        const NearLists lists{list_slots.data(), qs.data(), counts, best, slots, K};
        const auto full_search = [&](const Vec3d& p) { return exact.triangle_index[closest_triangle_bvh(exact, p).slot]; };
        int64_t bad = 0, missing = 0;
        for (const int stride : {1, 0}) {
            for (size_t first = 0; first < c.points.size(); first += K) {
                size_t index[K];
                for (int k = 0; k < K; ++k) index[k] = std::min(first + size_t(k * stride), c.points.size() - 1);
                const auto point_of = [&](int k) { return c.points[index[k]]; };
                BvhPacket<float, K> pk = unsearched_packet<K>(point_of);
                ListedCertifiedNear<float, K, decltype(point_of)> near(slack, point_of, lists, 0, K);
                if (seeded) seed_by_descent(view, pk, near);
                NoBvhStats none;
                closest_triangles_packet(view, pk, none, near);
                for (int k = 0; k < K; ++k) {
                    bool unused = false, reranked = false, overflow = false;
                    const int32_t winner = near.finish(view, k, pk, unused);
                    const Vec3d p = point_of(k);
                    const int32_t t = rerank_near_list(lists, k, slack, bvh.packed_double.data(), view.triangle_index, p,
                                                       winner, full_search, reranked, overflow);
                    listed_lanes += counts[k] > 1;
                    single_lanes += !reranked;
                    overflows += overflow;
                    const int got = mesh.source_triangle()[size_t(t)];
                    if (got != want[index[k]].triangle && bad++ < 3)
                        std::printf("  %s point %zu: listed %d, double brute force %d\n", c.mesh.name.c_str(), index[k], got,
                                    want[index[k]].triangle);
                    if (overflow) continue;
                    // Every triangle nearer than X = beyond_candidates_squared (nearest_side's
                    // bound) is listed; double's rounding is far below X - q, so halfway to X.
                    const double beyond = beyond_candidates_squared(slack, best[k]);
                    EXPECT_GT(beyond, double(best[k]));
                    for (size_t s = 0; s < bvh.packed_double.size(); ++s) {
                        if (!(squared_distance(bvh.packed_double[s], p.x, p.y, p.z) <= 0.5 * (double(best[k]) + beyond))) continue;
                        bool listed = false;
                        for (int c = 0; c < counts[k]; ++c) listed |= list_slots[size_t(c * K + k)] == view.triangle_index[s];
                        missing += !listed;
                    }
                }
            }
        }
        EXPECT_EQ(bad, 0) << c.mesh.name;
        EXPECT_EQ(missing, 0) << c.mesh.name;
    }
    std::printf("listed packets, %d entries%s: %lld lanes with several live candidates, %lld certified without double work, "
                "%lld overflows\n", slots, seeded ? ", seeded" : "", (long long)listed_lanes, (long long)single_lanes, (long long)overflows);
    EXPECT_GT(listed_lanes, 0);
    EXPECT_GT(single_lanes, 0);
    EXPECT_GT(overflows, 0);
}

TEST(CertifiedSearch, ListedPacketEqualsDoubleBruteForce) { check_listed_packets(kNearListSlots); }
TEST(CertifiedSearch, ShortListsDropOnlyWhatTheyRemember) { check_listed_packets(2); }

/// The GPU point lists seed every lane by its own descent before the walk: the seed is a best
/// like any other, and every candidate still reaches the list (or the streamed re-rank).
TEST(CertifiedSearch, SeededPacketsEqualDoubleBruteForce) {
    check_streamed_packets(true);
    check_listed_packets(kNearListSlots, true);
    check_listed_packets(2, true);
}

/// Lattices take the same path with bricks (packets) and per-point seeds: a lattice hugging
/// the cube's top face 1e-4 above it, and the fan plate's whole box.
TEST(CertifiedSearch, FloatLatticesEqualDoubleBruteForce) {
    const auto cases = adversarial_cases(2026, 10);
    for (const AdversarialCase& c : cases) {
        if (c.mesh.name != "cube" && c.mesh.name != "fan_plate") continue;
        const PreparedMesh mesh = prepare_mesh(c.mesh);
        Lattice lattice;
        lattice.type = LatticeType::CC;
        if (c.mesh.name == "cube") {  // 40 x 40 x 3 points, the lowest layer 1e-4 above the top face
            lattice.origin = {-0.5123, -0.5077, 0.5 + 1e-4};
            lattice.spacing = 1.0 / 37.0;
            lattice.resolution = {40, 40, 3};
        } else {
            lattice.origin = {-1.1, -1.1, -0.2};
            lattice.spacing = 2.2 / 23.0;
            lattice.resolution = {24, 24, 6};
        }
        const SampledField want = make_cpu_brute_force_sampler(options(Precision::Double, "vectorized"))->bind(share(mesh))->sample(lattice);
        for (const char* kernel : {"brick", "seeded", "unseeded"}) {
            const SampledField got = make_cpu_bvh_sampler(options(Precision::Float, kernel))->bind(share(mesh))->sample(lattice);
            int64_t bad = 0;
            for (size_t i = 0; i < got.distance.size(); ++i)
                bad += !(got.closest_triangle[i] == want.closest_triangle[i] && same_bits(got.distance[i], want.distance[i]));
            EXPECT_EQ(bad, 0) << c.mesh.name << " " << kernel;
            EXPECT_EQ(got.sampler.search_certificate->certified, true);
            std::printf("%-10s lattice %-9s re-ranked %lld of %lld points\n", c.mesh.name.c_str(), kernel,
                        (long long)got.timings.reranked_points, (long long)got.timings.certified_points);
        }
        const SampledField brute = make_cpu_brute_force_sampler(options(Precision::Float, "vectorized"))->bind(share(mesh))->sample(lattice);
        for (size_t i = 0; i < brute.distance.size(); ++i)
            ASSERT_TRUE(brute.closest_triangle[i] == want.closest_triangle[i] && same_bits(brute.distance[i], want.distance[i])) << i;
    }
}

}  // namespace
}  // namespace sdf
