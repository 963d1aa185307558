// The dispatched CPU kernels (cpu_reference/dispatch/cpu_kernels.h): every ISA level this CPU
// runs returns, bit for bit, what a plain scalar loop over squared_distance() returns (the
// nearest triangle, lowest index on ties, and its squared distance), for the brute force and
// the BVH packet traversal, in float and double; the one-point BVH query returns the bits of
// the same template compiled in this file (at the build's target), and the BVH kernels visit
// the same nodes at every level. The certified float kernels (search_certificate.h) keep the
// same winners, Q bits and candidates at every level as the templates compiled here, and their
// re-ranking gives the double brute force's triangle; the certified samplers at the chosen
// level equal the double brute force in distance, gradient and triangle (CTest runs this at
// SDF_CPU_ISA=v2, v3 and the widest level), and the sparse band's block sweep keeps the
// scalar loop's triangle at every point. Levels this CPU lacks are skipped; a build for one
// target (SDF_CPU_TARGET other than portable) has no levels and skips.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <random>

#include "core/bvh/triangle_bvh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/mesh/prepared_mesh.h"
#include "core/sampling/certified_search.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/dispatch/cpu_kernels.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "core/winding/winding_sign.h"
#include "core/lattice/lattice_fitting.h"
#include "kernels/lattice/band_sweep.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

template <typename T>
bool same_bits(T a, T b) {
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

/// The levels this build compiled and this CPU runs.
std::vector<const CpuKernelSet*> runnable_sets() {
    std::vector<const CpuKernelSet*> sets;
    for (CpuIsa isa : kCpuIsaLevels)
        if (const CpuKernelSet* s = cpu_kernel_set(isa)) sets.push_back(s);
    return sets;
}

/// Whether SDF_CPU_ISA names a level that this CPU lacks: the tests of the chosen level skip
/// (CTest forces x86-64-v3, which an old CPU may not run).
bool requested_level_missing() {
    const char* requested = std::getenv("SDF_CPU_ISA");
    return requested != nullptr && *requested != '\0' && !cpu_supports(parse_cpu_isa(requested, "SDF_CPU_ISA"));
}

/// Random points around the mesh, the mesh's vertices (exact ties between the triangles that
/// share them) and far points (large, nearly equal distances).
std::vector<Vec3d> query_points(const PreparedMesh& mesh, int n) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.6, 1.6);
    std::vector<Vec3d> pts;
    for (int i = 0; i < n; ++i) pts.push_back({u(rng), u(rng), u(rng)});
    for (size_t t = 0; t < mesh.triangles().size() && pts.size() < size_t(n) + 64; t += 7)
        pts.push_back(mesh.vertices()[size_t(mesh.triangles()[t][0])]);
    for (int i = 0; i < 32; ++i) pts.push_back({1e3 * u(rng), 1e3 * u(rng), 1e3 * u(rng)});
    while (pts.size() % kPointTile != 0) pts.push_back(pts.front());
    return pts;
}

const PreparedMesh& test_mesh() {
    static const PreparedMesh mesh = prepare_mesh(make_icosphere(3));  // 1,280 triangles
    return mesh;
}

template <typename T>
void check_brute_force_at_every_level() {
    const PreparedMesh& mesh = test_mesh();
    const auto& packed = mesh.buffers<T>().packed;
    const TriangleSoA<T> soa(packed);
    const MeshView<T> view = mesh.buffers<T>().view();
    const std::vector<Vec3d> pts = query_points(mesh, 512);
    const auto sets = runnable_sets();
    if (sets.empty()) GTEST_SKIP() << "a single-target build: one set of kernels, nothing to compare";
    int compared = 0;
    for (size_t first = 0; first < pts.size(); first += kPointTile) {
        T px[kPointTile], py[kPointTile], pz[kPointTile];
        for (int k = 0; k < kPointTile; ++k) {
            px[k] = T(pts[first + k].x);
            py[k] = T(pts[first + k].y);
            pz[k] = T(pts[first + k].z);
        }
        for (const CpuKernelSet* set : sets) {
            int best[kPointTile];
            T q[kPointTile];
            set->get<T>().nearest_triangles(soa, kPointTile, px, py, pz, best, q);
            for (int k = 0; k < kPointTile; ++k) {
                int want = -1;  // the scalar reference: strictly smaller wins, so the lowest index on ties
                T want_q = std::numeric_limits<T>::infinity();
                for (size_t t = 0; t < packed.size(); ++t) {
                    const T d = squared_distance(packed[t], px[k], py[k], pz[k]);
                    if (d < want_q) { want_q = d; want = int(t); }
                }
                ASSERT_EQ(best[k], want) << set->isa << ", point " << first + k;
                ASSERT_TRUE(same_bits(q[k], want_q)) << set->isa << ", point " << first + k << ": " << q[k] << " vs " << want_q;
                const Vec3<T> p(px[k], py[k], pz[k]);  // the thesis's kernel: the template compiled here
                ASSERT_EQ(set->get<T>().nearest_triangle_eberly(view, p), nearest_triangle_eberly(view, p)) << set->isa;
                ++compared;
            }
        }
    }
    std::printf("brute force, %zu-byte floats: %d results at %zu levels equal the scalar loop bit for bit\n", sizeof(T),
                compared, sets.size());
}

TEST(CpuIsa, BruteForceEqualsTheScalarLoopAtEveryLevelFloat) { check_brute_force_at_every_level<float>(); }
TEST(CpuIsa, BruteForceEqualsTheScalarLoopAtEveryLevelDouble) { check_brute_force_at_every_level<double>(); }

template <typename T>
void check_bvh_at_every_level() {
    const PreparedMesh& mesh = test_mesh();
    const TriangleBvh bvh = build_triangle_bvh(mesh);
    const BvhView<T> view = bvh.view<T>();
    const std::vector<Vec3d> pts = query_points(mesh, 512);
    const auto sets = runnable_sets();
    if (sets.empty()) GTEST_SKIP() << "a single-target build: one set of kernels, nothing to compare";
    // The scalar reference: the minimum over all triangles, lowest triangle index on ties (the BVH's tie rule).
    auto reference = [&](const Vec3<T>& p, int32_t& triangle) {
        T best = std::numeric_limits<T>::infinity();
        triangle = -1;
        for (int s = 0; s < view.num_triangles; ++s) {
            const T d = squared_distance(view.packed[s], p);
            if (d < best || (d == best && view.triangle_index[s] < triangle)) { best = d; triangle = view.triangle_index[s]; }
        }
        return best;
    };
    BvhStats first_stats;
    for (size_t level = 0; level < sets.size(); ++level) {
        const CpuKernels<T>& kernels = sets[level]->get<T>();
        BvhStats stats;
        for (size_t first = 0; first < pts.size(); first += kCpuPacketLanes) {
            BvhPacket<T, kCpuPacketLanes> pk;
            int32_t seed[kCpuPacketLanes];
            for (int k = 0; k < kCpuPacketLanes; ++k) {
                pk.x[k] = T(pts[first + k].x);
                pk.y[k] = T(pts[first + k].y);
                pk.z[k] = T(pts[first + k].z);
                seed[k] = -1;
            }
            seed_packet(view, seed, pk);
            kernels.closest_triangles_packet(view, pk, stats);
            for (int k = 0; k < kCpuPacketLanes; ++k) {
                const Vec3<T> p(pk.x[k], pk.y[k], pk.z[k]);
                int32_t want_triangle = -1;
                const T want = reference(p, want_triangle);
                ASSERT_TRUE(same_bits(pk.best_q[k], want)) << sets[level]->isa << ", point " << first + k;
                ASSERT_EQ(view.triangle_index[pk.best_slot[k]], want_triangle) << sets[level]->isa << ", point " << first + k;
                // The one-point query may stop at a triangle within the rounding of the box
                // distances (far points in float): its truth is the template compiled here.
                const BvhHit<T> hit = kernels.closest_triangle(view, p, BvhHit<T>{}, stats);
                const BvhHit<T> here = closest_triangle_bvh(view, p);
                ASSERT_TRUE(same_bits(hit.distance_squared, here.distance_squared)) << sets[level]->isa << ", point " << first + k;
                ASSERT_EQ(hit.slot, here.slot) << sets[level]->isa << ", point " << first + k;
            }
        }
        if (level == 0) first_stats = stats;
        EXPECT_EQ(stats.nodes, first_stats.nodes) << sets[level]->isa << " traversed differently from " << sets[0]->isa;
        EXPECT_EQ(stats.triangles, first_stats.triangles) << sets[level]->isa;
    }
    std::printf("BVH, %zu-byte floats: %zu points at %zu levels equal the scalar loop bit for bit (%lld nodes each)\n",
                sizeof(T), pts.size(), sets.size(), (long long)first_stats.nodes);
}

TEST(CpuIsa, BvhKernelsEqualTheScalarLoopAtEveryLevelFloat) { check_bvh_at_every_level<float>(); }
TEST(CpuIsa, BvhKernelsEqualTheScalarLoopAtEveryLevelDouble) { check_bvh_at_every_level<double>(); }

/// The candidates a certified search kept, in the order kept, with the bits of their Q and
/// the smallest dropped Q: equal lists mean the same search, step for step.
template <int N>
std::vector<int64_t> kept(const NearCandidates<float, N>& c) {
    std::vector<int64_t> out;
    for (int i = 0; i < c.count; ++i) {
        uint32_t bits;
        std::memcpy(&bits, &c.q[i], sizeof bits);
        out.push_back(int64_t(c.slot[i]) << 32 | bits);
    }
    uint32_t dropped;
    std::memcpy(&dropped, &c.dropped, sizeof dropped);
    out.push_back(dropped);
    return out;
}

std::vector<int64_t> kept(const AllNear& c) {
    std::vector<int64_t> out;
    for (size_t i = 0; i < c.slot.size(); ++i) {
        uint32_t bits;
        std::memcpy(&bits, &c.q[i], sizeof bits);
        out.push_back(int64_t(c.slot[i]) << 32 | bits);
    }
    return out;
}

/// The double search's triangle at p: the scalar loop over squared_distance() in double,
/// lowest triangle index on ties (prepared-mesh order).
int32_t double_brute_force(const PreparedMesh& mesh, const Vec3d& p) {
    const auto& packed = mesh.buffers<double>().packed;
    int32_t best = -1;
    double best_q = std::numeric_limits<double>::infinity();
    for (size_t t = 0; t < packed.size(); ++t) {
        const double d = squared_distance(packed[t], p.x, p.y, p.z);
        if (d < best_q) { best_q = d; best = int32_t(t); }
    }
    return best;
}

/// The certified float kernels (search_certificate.h) at every level: the brute force, the
/// one-point BVH query and the packet keep the same winner, Q bits and candidates as the same
/// templates compiled in this file; the fallbacks that keep every candidate too; and the
/// re-ranking in double turns them into the double brute force's triangle.
TEST(CpuIsa, CertifiedKernelsAgreeAtEveryLevelAndCertify) {
    const PreparedMesh& mesh = test_mesh();
    const TriangleBvh bvh = build_triangle_bvh(mesh);
    const BvhView<float> view = bvh.view<float>();
    const BvhView<double> exact = bvh.view<double>();
    const TriangleSoA<float> soa(mesh.buffers<float>().packed);
    const PackedTriangle<double>* exact_ordered = mesh.buffers<double>().packed.data();
    const std::vector<Vec3d> pts = query_points(mesh, 512);
    const auto sets = runnable_sets();
    if (sets.empty()) GTEST_SKIP() << "a single-target build: one set of kernels, nothing to compare";
    double coordinate = 0;
    for (const Vec3d& p : pts) coordinate = std::max(coordinate, largest_coordinate(p));
    const SearchSlack<float> slack = make_search_slack(float_search_bound(mesh), coordinate);
    ASSERT_TRUE(slack.certify);
    std::vector<int32_t> truth;
    for (const Vec3d& p : pts) truth.push_back(double_brute_force(mesh, p));
    int64_t reranked = 0, overflowed = 0;
    for (const CpuKernelSet* set : sets) {
        const CpuCertifiedKernels& k = set->certified;
        BvhStats stats, here_stats;
        for (size_t first = 0; first < pts.size(); first += kCpuPacketLanes) {
            float px[kPointTile], py[kPointTile], pz[kPointTile];
            BvhPacket<float, kCpuPacketLanes> pk, here_pk;
            int32_t seed[kCpuPacketLanes];
            for (int i = 0; i < kPointTile; ++i) {
                px[i] = pk.x[i] = here_pk.x[i] = float(pts[first + i].x);
                py[i] = pk.y[i] = here_pk.y[i] = float(pts[first + i].y);
                pz[i] = pk.z[i] = here_pk.z[i] = float(pts[first + i].z);
                seed[i] = -1;
            }
            // The brute force: a tile of points.
            CpuCertifiedNear near[kPointTile], here_near[kPointTile];
            for (int i = 0; i < kPointTile; ++i) near[i].slack = here_near[i].slack = slack;
            int best[kPointTile], here_best[kPointTile];
            float q[kPointTile], here_q[kPointTile];
            k.nearest_triangles(soa, kPointTile, px, py, pz, best, q, near);
            nearest_triangles_vectorized(soa, kPointTile, px, py, pz, here_best, here_q, here_near);
            // The packet.
            seed_packet(view, seed, pk);
            seed_packet(view, seed, here_pk);
            CpuPacketCertifiedNear pnear, here_pnear;
            pnear.slack = here_pnear.slack = slack;
            k.closest_triangles_packet(view, pk, stats, pnear);
            closest_triangles_packet(view, here_pk, here_stats, here_pnear);
            for (int i = 0; i < kPointTile; ++i) {
                const size_t n = first + size_t(i);
                const Vec3d& p = pts[n];
                const Vec3f pf(px[i], py[i], pz[i]);
                const std::string where = std::string(set->isa) + ", point " + std::to_string(n);
                ASSERT_EQ(best[i], here_best[i]) << where;
                ASSERT_TRUE(same_bits(q[i], here_q[i])) << where;
                ASSERT_EQ(kept(near[i].near), kept(here_near[i].near)) << where;
                ASSERT_EQ(pk.best_slot[i], here_pk.best_slot[i]) << where;
                ASSERT_TRUE(same_bits(pk.best_q[i], here_pk.best_q[i])) << where;
                ASSERT_EQ(kept(pnear.near[i]), kept(here_pnear.near[i])) << where;
                // The one-point query and its fallback.
                CpuCertifiedNear one{slack, {}}, here_one{slack, {}};
                const BvhHit<float> hit = k.closest_triangle(view, pf, BvhHit<float>{}, stats, one);
                const BvhHit<float> here_hit = closest_triangle_bvh(view, pf, BvhHit<float>{}, here_stats, here_one);
                ASSERT_EQ(hit.slot, here_hit.slot) << where;
                ASSERT_TRUE(same_bits(hit.distance_squared, here_hit.distance_squared)) << where;
                ASSERT_EQ(kept(one.near), kept(here_one.near)) << where;
                AllNear all{slack, {}, {}}, here_all{slack, {}, {}};
                const BvhHit<float> wide = k.closest_triangle_all(view, pf, BvhHit<float>{}, stats, all);
                closest_triangle_bvh(view, pf, BvhHit<float>{}, here_stats, here_all);
                ASSERT_EQ(kept(all), kept(here_all)) << where;
                AllNear tile_all{slack, {}, {}}, here_tile_all{slack, {}, {}};
                int one_best, here_one_best;
                float one_q, here_one_q;
                k.nearest_triangles_all(soa, 1, &pf.x, &pf.y, &pf.z, &one_best, &one_q, &tile_all);
                nearest_triangles_vectorized(soa, 1, &pf.x, &pf.y, &pf.z, &here_one_best, &here_one_q, &here_tile_all);
                ASSERT_EQ(kept(tile_all), kept(here_tile_all)) << where;
                // Every search, re-ranked in double, returns the double brute force's triangle:
                // from its kept candidates, or (overflow) from every candidate.
                auto certified = [&](int32_t winner, float best_q, const NearCandidates<float, kCpuNearCandidates>& c,
                                     const int32_t* index, const PackedTriangle<double>* packed, const AllNear& every) {
                    const float radius = slack.radius(best_q);
                    Rerank r = k.rerank(packed, index, p, winner, radius, c.slot, c.q, c.count, c.dropped);
                    auto index_of = [&](int32_t s) { return index ? index[s] : s; };
                    const Rerank here = rerank_in_double(packed, index_of, p.x, p.y, p.z, winner, radius, c);
                    EXPECT_EQ(r.slot, here.slot) << where;
                    EXPECT_EQ(r.overflow, here.overflow) << where;
                    reranked += r.reranked;
                    if (r.overflow) {
                        ++overflowed;
                        r = k.rerank(packed, index, p, winner, radius, every.slot.data(), every.q.data(),
                                     int(every.slot.size()), NAN);
                    }
                    return index_of(r.slot);
                };
                EXPECT_EQ(certified(best[i], q[i], near[i].near, nullptr, exact_ordered, tile_all), truth[n]) << where << " brute force";
                EXPECT_EQ(certified(pk.best_slot[i], pk.best_q[i], pnear.near[i], view.triangle_index, exact.packed, all),
                          truth[n]) << where << " packet";
                EXPECT_EQ(certified(hit.slot, hit.distance_squared, one.near, view.triangle_index, exact.packed, all), truth[n])
                    << where << " one point";
                EXPECT_EQ(view.triangle_index[wide.slot], view.triangle_index[hit.slot]) << where;
            }
        }
        EXPECT_EQ(stats.nodes, here_stats.nodes) << set->isa << " traversed differently from this file's kernels";
        EXPECT_EQ(stats.triangles, here_stats.triangles) << set->isa;
    }
    EXPECT_GT(reranked, 0);  // the vertices: exact ties between the triangles around them
    std::printf("certified float kernels: %zu points at %zu levels; %lld searches re-ranked in double, %lld overflowed\n",
                pts.size(), sets.size(), (long long)reranked, (long long)overflowed);
}

SamplerOptions float_options(const std::string& kernel) {
    SamplerOptions o;
    o.precision = Precision::Float;
    o.kernel = kernel;
    o.progress = false;
    return o;
}

/// The certified float samplers at the level this process runs (CTest runs this test at
/// x86-64-v2, -v3 and the widest level): distance, gradient and triangle bit for bit those of
/// the double brute force, on point lists (brute force, BVH packets, seeded, unseeded) and on
/// a lattice; most points are nearest to a vertex or an edge, where the triangles around it
/// tie exactly and are re-ranked in double.
TEST(CpuIsa, CertifiedSamplersEqualTheDoubleBruteForce) {
    if (requested_level_missing()) GTEST_SKIP() << "SDF_CPU_ISA names a level this CPU lacks";
    const PreparedMesh& mesh = test_mesh();
    const std::vector<Vec3d> pts = query_points(mesh, 256);
    SamplerOptions reference = float_options("vectorized");
    reference.precision = Precision::Double;
    const std::vector<PointSample> want = make_cpu_brute_force_sampler(reference)->bind(share(mesh))->query(pts);
    auto same_sample = [](const PointSample& a, const PointSample& b) {
        return a.triangle == b.triangle && same_bits(a.distance, b.distance) && same_bits(a.gradient.x, b.gradient.x) &&
               same_bits(a.gradient.y, b.gradient.y) && same_bits(a.gradient.z, b.gradient.z);
    };
    struct Run { const char* method; const char* kernel; };
    for (const Run r : {Run{"brute_force", "vectorized"}, Run{"bvh", "brick"}, Run{"bvh", "seeded"}, Run{"bvh", "unseeded"}}) {
        const SamplerOptions o = float_options(r.kernel);
        auto sampler = std::string(r.method) == "bvh" ? make_cpu_bvh_sampler(o) : make_cpu_brute_force_sampler(o);
        SamplingTimings timings;
        const std::vector<PointSample> got = sampler->bind(share(mesh))->query(pts, &timings);
        int64_t bad = 0;
        for (size_t i = 0; i < pts.size(); ++i) bad += !same_sample(got[i], want[i]);
        EXPECT_EQ(bad, 0) << active_cpu_kernels().isa << " " << r.method << "/" << r.kernel;
        EXPECT_GT(timings.reranked_points, 0);
    }
    const Lattice lattice{LatticeType::CC, {-1.25, -1.25, -1.25}, 0.125, {21, 21, 21}};
    const SampledField lattice_want = make_cpu_brute_force_sampler(reference)->bind(share(mesh))->sample(lattice);
    for (const Run r : {Run{"brute_force", "vectorized"}, Run{"bvh", "brick"}, Run{"bvh", "seeded"}, Run{"bvh", "unseeded"}}) {
        const SamplerOptions o = float_options(r.kernel);
        auto sampler = std::string(r.method) == "bvh" ? make_cpu_bvh_sampler(o) : make_cpu_brute_force_sampler(o);
        const SampledField got = sampler->bind(share(mesh))->sample(lattice);
        ASSERT_EQ(got.distance.size(), lattice_want.distance.size());
        int64_t bad = 0;
        for (size_t i = 0; i < got.distance.size(); ++i)
            bad += !(got.closest_triangle[i] == lattice_want.closest_triangle[i] && same_bits(got.distance[i], lattice_want.distance[i]) &&
                     same_bits(got.gradient[i].x, lattice_want.gradient[i].x) && same_bits(got.gradient[i].y, lattice_want.gradient[i].y) &&
                     same_bits(got.gradient[i].z, lattice_want.gradient[i].z));
        EXPECT_EQ(bad, 0) << active_cpu_kernels().isa << " lattice " << r.method << "/" << r.kernel;
        EXPECT_EQ(got.sampler.search_certificate->certified, true);
    }
    std::printf("certified samplers at %s: %zu points and a %lld-point lattice equal the double brute force\n",
                active_cpu_kernels().isa, pts.size(), (long long)lattice.num_points());
}

/// A torus with every fifth triangle removed: open, so its winding numbers take every value
/// between 0 and 1 near the holes, where a wrong term or order would show.
const PreparedMesh& holed_mesh() {
    static const PreparedMesh mesh = [] {
        TriangleMesh m = make_torus(1.0, 0.35, 48, 24);
        std::vector<Int3> kept;
        for (size_t t = 0; t < m.triangles.size(); ++t)
            if (t % 5 != 0) kept.push_back(m.triangles[t]);
        m.triangles = kept;
        return prepare_mesh(m);
    }();
    return mesh;
}

/// The packet of fast winding numbers (fast_winding_packet.h) gives every lane the bits of
/// WindingSign's own evaluation of its point, at every level and the chosen one, at the
/// samplers' accuracy and others: on lattice-like bricks (coherent lanes, as the samplers
/// run it), on packets of scattered points (lanes that open different nodes), on vertices
/// and far away. The same for the packet of certified sides (certified_winding_packet.h).
TEST(CpuIsa, WindingPacketEqualsThePointEvaluationAtEveryLevel) {
    if (requested_level_missing()) GTEST_SKIP() << "SDF_CPU_ISA names a level this CPU lacks";
    constexpr int K = kCpuPacketLanes;
    std::vector<const CpuKernelSet*> sets = runnable_sets();
    sets.push_back(&active_cpu_kernels());
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.6, 1.6), spacing(1e-3, 0.2);
    for (const PreparedMesh* mesh : {&holed_mesh(), &test_mesh()}) {
        std::vector<Vec3d> pts;
        for (int b = 0; b < 64; ++b) {  // 4 x 2 x 2 bricks
            const Vec3d o{u(rng), u(rng), 0.3 * u(rng)};
            const double h = spacing(rng);
            for (int k = 0; k < K; ++k) pts.push_back(o + Vec3d{h * (k % 4), h * ((k / 4) % 2), h * (k / 8)});
        }
        for (int i = 0; i < 64 * K; ++i) pts.push_back({u(rng), u(rng), 0.5 * u(rng)});
        for (size_t v = 0; v < mesh->vertices().size() && v < size_t(4 * K); v += 3) pts.push_back(mesh->vertices()[v]);
        for (int i = 0; i < 2 * K; ++i) pts.push_back({1e3 * u(rng), 1e3 * u(rng), 1e3 * u(rng)});
        while (pts.size() % K != 0) pts.push_back(pts.front());
        for (const WindingAccuracy<double> acc : {WindingAccuracy<double>{}, WindingAccuracy<double>{1.5, 1},
                                                  WindingAccuracy<double>{3.0, 2}}) {
            WindingSignOptions options;
            options.accuracy = acc;
            const WindingSign sign(*mesh, options);
            for (const CpuKernelSet* set : sets) {
                int64_t bad = 0, between = 0, certified_bad = 0, refined = 0;
                for (size_t first = 0; first < pts.size(); first += K) {
                    double px[K], py[K], pz[K], value[K];
                    for (int k = 0; k < K; ++k) {
                        px[k] = pts[first + size_t(k)].x;
                        py[k] = pts[first + size_t(k)].y;
                        pz[k] = pts[first + size_t(k)].z;
                    }
                    set->winding_numbers_packet(sign.view(), px, py, pz, acc, value);
                    for (int k = 0; k < K; ++k) {
                        const double want = sign.estimate(pts[first + size_t(k)]).value;
                        bad += !same_bits(value[k], want);
                        between += want > 0.05 && want < 0.95;
                    }
                    // The certified sides (certified_winding_packet.h): each lane's side and
                    // stage, and its first estimate bit for bit, are its point's own.
                    WindingSide side[K];
                    set->winding_sides_packet(sign.view(), &pts[first], K, acc, options.certification, side);
                    int64_t lanes[K];
                    double certified[K], certified_bound[K];
                    for (int k = 0; k < K; ++k) lanes[k] = 1;
                    certified_winding_numbers_packet<K>(sign.view(), &pts[first], lanes, acc, certified, certified_bound);
                    for (int k = 0; k < K; ++k) {
                        const WindingSide want = certified_winding_side(sign.view(), pts[first + size_t(k)], acc, options.certification);
                        certified_bad += side[k].inside != want.inside || side[k].stage != want.stage;
                        const WindingEstimate<double> e = certified_winding_number(sign.view(), pts[first + size_t(k)], acc);
                        certified_bad += !same_bits(certified[k], e.value) || !same_bits(certified_bound[k], e.error_bound);
                        refined += want.stage != WindingStage::Fast;
                    }
                }
                EXPECT_EQ(bad, 0) << set->isa << " beta " << acc.beta << " order " << acc.order;
                EXPECT_EQ(certified_bad, 0) << set->isa << " beta " << acc.beta << " order " << acc.order;
                EXPECT_GT(refined, 0) << set->isa << " beta " << acc.beta << ": the ladder should be exercised";
                if (mesh == &holed_mesh()) {
                    EXPECT_GT(between, 100) << "the holes should give fractional winding numbers";
                }
            }
        }
    }
}

/// The dispatched re-ranking (rerank_simd.h: the candidates' double Q in one vector loop, in
/// chunks of kRerankChunk) returns what rerank_in_double() returns, at every level: on the
/// mesh's vertices (every triangle around one ties in exact arithmetic, and double's
/// rounding decides), near them, and with up to 40 candidates (several chunks), some beyond
/// the radius, duplicates, and a dropped one within it (overflow).
TEST(CpuIsa, RerankEqualsTheScalarReRanking) {
    if (requested_level_missing()) GTEST_SKIP() << "SDF_CPU_ISA names a level this CPU lacks";
    const PreparedMesh& mesh = test_mesh();
    const TriangleBvh bvh = build_triangle_bvh(mesh);
    const BvhView<double> exact = bvh.view<double>();
    std::vector<const CpuKernelSet*> sets = runnable_sets();
    sets.push_back(&active_cpu_kernels());
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> jitter(-1e-9, 1e-9), unit(0.0, 1.0);
    const int n = exact.num_triangles;
    int64_t cases = 0, reranked = 0, changed = 0;
    for (size_t v = 0; v < mesh.vertices().size(); v += 2) {
        const Vec3d p = mesh.vertices()[v] * (1.0 + 1e-3 * unit(rng)) + Vec3d{jitter(rng), jitter(rng), jitter(rng)};
        // The slots of the triangles around vertex v first (the ties), then random ones.
        std::vector<int32_t> slots;
        for (int s = 0; s < n; ++s) {
            const Int3 t = mesh.triangles()[size_t(exact.triangle_index[s])];
            if (t[0] == int(v) || t[1] == int(v) || t[2] == int(v)) slots.push_back(s);
        }
        const int extra = int(rng() % 34);
        for (int i = 0; i < extra; ++i) slots.push_back(int32_t(rng() % uint64_t(n)));
        std::shuffle(slots.begin(), slots.end(), rng);
        const float radius = 1.0f;
        std::vector<float> q(slots.size());
        for (float& x : q) x = float(unit(rng) < 0.8 ? 0.5 : 1.5);  // 1 in 5 beyond the radius
        const int32_t winner = slots[0];
        const float dropped = unit(rng) < 0.05 ? 0.75f : NAN;
        const auto index_of = [&](int32_t s) { return exact.triangle_index[s]; };
        const Rerank want = rerank_in_double(exact.packed, index_of, p.x, p.y, p.z, winner, radius, slots.data(), q.data(),
                                             int(slots.size()), dropped);
        for (const CpuKernelSet* set : sets) {
            const Rerank got = set->certified.rerank(exact.packed, exact.triangle_index, p, winner, radius, slots.data(),
                                                     q.data(), int(slots.size()), dropped);
            EXPECT_EQ(got.slot, want.slot) << set->isa << " vertex " << v;
            EXPECT_EQ(got.reranked, want.reranked) << set->isa << " vertex " << v;
            EXPECT_EQ(got.overflow, want.overflow) << set->isa << " vertex " << v;
        }
        ++cases;
        reranked += want.reranked;
        changed += want.slot != winner;
    }
    EXPECT_GT(reranked, cases / 2);
    EXPECT_GT(changed, cases / 4) << "the double search should overrule the float winner often here";
}

/// The dispatched band sweep (band_sweep.h: a block's rows against its candidate triangles,
/// vectorised, with its culls) keeps at each point of a block the triangle that a scalar loop
/// over every triangle keeps (the least squared_distance() within the bound, the lower index on
/// ties), and its Q bits, at every level: the fanned tetrahedron (slivers down to 2^-30 wide,
/// lattice points on their shared edge: exact ties) and the icosphere, blocks cut by the
/// lattice's end (padding never won), candidates in a shuffled order, and a bound that leaves
/// some points without a triangle.
TEST(CpuIsa, BandSweepEqualsTheScalarLoopAtEveryLevel) {
    if (requested_level_missing()) GTEST_SKIP() << "SDF_CPU_ISA names a level this CPU lacks";
    std::vector<const CpuKernelSet*> sets = runnable_sets();
    sets.push_back(&active_cpu_kernels());
    const PreparedMesh fan = prepare_mesh(test::fanned_tetrahedron());
    std::mt19937_64 rng(11);
    int64_t points = 0, found = 0, ties = 0;
    for (const PreparedMesh* mesh : {&fan, &test_mesh()}) {
        const TriangleBvh bvh = build_triangle_bvh(*mesh);
        const BvhView<double> exact = bvh.view<double>();
        const Lattice lattice = mesh == &fan ? test::lattice_through_the_fan(LatticeType::CC)
                                             : fit_lattice(LatticeType::CC, {20, 19, 21}, mesh->bounds(), 0.2);
        const double bound = std::pow(2.5 * lattice.spacing, 2);
        std::vector<int32_t> slots(size_t(exact.num_triangles));
        for (int32_t s = 0; s < exact.num_triangles; ++s) slots[size_t(s)] = s;
        for (int bz = 0; bz * kBandBlockDim < lattice.resolution.z; ++bz)
            for (int by = 0; by * kBandBlockDim < lattice.resolution.y; ++by)
                for (int bx = 0; bx * kBandBlockDim < lattice.resolution.x; ++bx) {
                    const Int3 p0{bx * kBandBlockDim, by * kBandBlockDim, bz * kBandBlockDim};
                    BandSweepBlock block;
                    block.points = {std::min(kBandBlockDim, lattice.resolution.x - p0.x),
                                    std::min(kBandBlockDim, lattice.resolution.y - p0.y),
                                    std::min(kBandBlockDim, lattice.resolution.z - p0.z)};
                    block.margin = lattice.half_spacing();
                    block.rounding = 1e-12;
                    for (int k = 0; k < kBandBlockDim; ++k) {
                        const Vec3d p = lattice.position_of_coords({2 * (p0.x + k), 2 * (p0.y + k), 2 * (p0.z + k)});
                        block.x[k] = p.x;
                        block.y[k] = p.y;
                        block.z[k] = p.z;
                    }
                    std::shuffle(slots.begin(), slots.end(), rng);
                    std::vector<double> want_q(kBandBlockPoints, -1.0);  // padding: -1 (a Q may round below 0)
                    std::vector<int32_t> want(kBandBlockPoints, -1);
                    std::vector<bool> real(kBandBlockPoints, false);
                    for (int i = 0; i < kBandBlockPoints; ++i) {
                        const int x = i % kBandBlockDim, y = (i / kBandBlockDim) % kBandBlockDim, z = i / (kBandBlockDim * kBandBlockDim);
                        if (x >= block.points.x || y >= block.points.y || z >= block.points.z) continue;  // padding
                        real[size_t(i)] = true;
                        want_q[size_t(i)] = bound;
                        for (int32_t s = 0; s < exact.num_triangles; ++s) {
                            const double q = squared_distance(exact.packed[s], block.x[x], block.y[y], block.z[z]);
                            const int32_t t = exact.triangle_index[s];
                            if (q < want_q[size_t(i)] || (q == want_q[size_t(i)] && wins_tie(t, want[size_t(i)]))) {
                                ties += q == want_q[size_t(i)] && want[size_t(i)] >= 0;
                                want_q[size_t(i)] = q;
                                want[size_t(i)] = t;
                            }
                        }
                        ++points;
                        found += want[size_t(i)] >= 0;
                    }
                    for (const CpuKernelSet* set : sets) {
                        std::vector<double> q(kBandBlockPoints);
                        std::vector<int32_t> t(kBandBlockPoints, -1);
                        for (int i = 0; i < kBandBlockPoints; ++i) q[size_t(i)] = real[size_t(i)] ? bound : -1.0;
                        set->sweep_band_block(exact.packed, exact.triangle_index, slots.data(), int(slots.size()), block, bound,
                                              q.data(), t.data());
                        for (int i = 0; i < kBandBlockPoints; ++i) {
                            ASSERT_EQ(t[size_t(i)], want[size_t(i)]) << set->isa << " " << mesh->name() << " block " << bx << " "
                                                                     << by << " " << bz << " point " << i;
                            if (want[size_t(i)] >= 0) {
                                ASSERT_TRUE(same_bits(q[size_t(i)], want_q[size_t(i)])) << set->isa << " point " << i;
                            }
                        }
                    }
                }
    }
    EXPECT_GT(found, points / 10);
    EXPECT_LT(found, points);
    EXPECT_GT(ties, 0) << "points on the fan's shared edge tie";
}

TEST(CpuIsa, ParsesLevelNames) {
    EXPECT_EQ(parse_cpu_isa("v2", "test"), CpuIsa::X86_64_V2);
    EXPECT_EQ(parse_cpu_isa("x86-64-v3", "test"), CpuIsa::X86_64_V3);
    EXPECT_EQ(parse_cpu_isa("v4", "test"), CpuIsa::X86_64_V4);
    for (const char* bad : {"v1", "v5", "avx512", "V4", " v4", "x86-64"}) {
        try {
            parse_cpu_isa(bad, "environment variable SDF_CPU_ISA");
            ADD_FAILURE() << bad << " accepted";
        } catch (const std::runtime_error& e) {
            EXPECT_NE(std::string(e.what()).find("SDF_CPU_ISA"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("v2, v3, v4"), std::string::npos) << e.what();
        }
    }
}

TEST(CpuIsa, ChoosesTheWidestLevelOrTheRequestedOne) {
    if (requested_level_missing()) GTEST_SKIP() << "SDF_CPU_ISA names a level this CPU lacks";
    const CpuKernelChoice choice = cpu_kernel_choice();
    std::printf("kernels: %s (chosen by %s)\n", choice.isa.c_str(), choice.chosen_by.c_str());
    EXPECT_EQ(choice.isa, active_cpu_kernels().isa);
    const auto sets = runnable_sets();
    if (sets.empty()) {
        EXPECT_EQ(choice.chosen_by, "build target");
        EXPECT_THROW(select_cpu_kernels("v2"), std::runtime_error);
        return;
    }
    const char* requested = std::getenv("SDF_CPU_ISA");
    if (requested != nullptr && *requested != '\0') {
        EXPECT_EQ(choice.chosen_by, "SDF_CPU_ISA");
        EXPECT_EQ(choice.isa, cpu_isa_name(parse_cpu_isa(requested, "SDF_CPU_ISA")));
    } else {
        EXPECT_EQ(choice.chosen_by, "cpu");
        EXPECT_EQ(choice.isa, sets.back()->isa);  // the widest this CPU runs
    }
    for (CpuIsa isa : kCpuIsaLevels) {
        const std::string name = cpu_isa_name(isa);
        if (cpu_supports(isa)) {
            EXPECT_EQ(select_cpu_kernels(name).isa, name);
        } else {
            try {  // a level the CPU lacks is refused, never run
                select_cpu_kernels(name);
                ADD_FAILURE() << name << " selected on a CPU without it";
            } catch (const std::runtime_error& e) {
                EXPECT_NE(std::string(e.what()).find("cannot run " + name), std::string::npos) << e.what();
            }
        }
    }
    EXPECT_THROW(select_cpu_kernels("v9"), std::runtime_error);
}

}  // namespace
}  // namespace sdf
