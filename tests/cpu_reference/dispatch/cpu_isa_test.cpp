// The dispatched CPU kernels (cpu_reference/dispatch/cpu_kernels.h): every ISA level this CPU
// runs returns, bit for bit, what a plain scalar loop over squared_distance() returns (the
// nearest triangle, lowest index on ties, and its squared distance), for the brute force and
// the BVH packet traversal, in float and double; the one-point BVH query returns the bits of
// the same template compiled in this file (at the build's target), and the BVH kernels visit
// the same nodes at every level. Levels this CPU lacks are skipped; a build for one target
// (SDF_CPU_TARGET other than portable) has no levels and skips. SDF_CPU_ISA chooses the level.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <random>

#include "core/bvh/triangle_bvh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/mesh/prepared_mesh.h"
#include "cpu_reference/dispatch/cpu_kernels.h"

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
    const std::vector<PackedTriangle<T>>& packed = mesh.buffers<T>().packed;
    const TriangleSoA<T> soa(packed);
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
