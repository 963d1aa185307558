// The BVH belongs to its mesh (PreparedMesh::bvh()): built once per mesh however many
// samplers and calls use it, by preparation's self-intersection check or on first use, shared
// by copies, and never another mesh's, even one made at the same address from the same file.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <memory>
#include <new>
#include <thread>
#include <vector>

#include "core/bvh/triangle_bvh.h"
#include "core/lattice/lattice_fitting.h"
#include "core/mesh/prepared_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

MeshPreparationOptions without_intersection_check() {
    MeshPreparationOptions o;
    o.detect_intersections = false;
    return o;
}

SamplerOptions quiet(SignMode sign = SignMode::Auto) {
    SamplerOptions o;
    o.progress = false;
    o.threads = 2;
    o.sign = sign;
    return o;
}

/// The same tree, node for node and slot for slot.
void expect_same_tree(const TriangleBvh& a, const TriangleBvh& b) {
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)), 0);
    EXPECT_EQ(a.triangle_index, b.triangle_index);
}

void expect_same_field(const SampledField& a, const SampledField& b) {
    ASSERT_EQ(a.distance.size(), b.distance.size());
    EXPECT_EQ(std::memcmp(a.distance.data(), b.distance.data(), a.distance.size() * sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(a.gradient.data(), b.gradient.data(), a.gradient.size() * sizeof(Vec3d)), 0);
    EXPECT_EQ(a.closest_triangle, b.closest_triangle);
}

bool built_by_bind(const SampledField& f) { return f.sampler.details.at("bvh").at("built_by_bind").get<bool>(); }

TEST(MeshBvh, BuiltOnceOnFirstUseAndSharedByCopies) {
    const PreparedMesh mesh = prepare_mesh(make_torus(1.0, 0.3, 24, 12), without_intersection_check());
    bool built = false;
    const std::shared_ptr<const TriangleBvh> first = mesh.bvh(&built);
    EXPECT_TRUE(built);
    EXPECT_EQ(mesh.bvh(&built), first);
    EXPECT_FALSE(built);
    const PreparedMesh copy = mesh;  // the same content: the same tree
    EXPECT_EQ(copy.bvh(&built), first);
    EXPECT_FALSE(built);
    expect_same_tree(*first, build_triangle_bvh(mesh));
}

TEST(MeshBvh, PreparationKeepsTheTreeOfItsIntersectionCheck) {
    const PreparedMesh mesh = prepare_mesh(make_torus(1.0, 0.3, 24, 12));
    ASSERT_TRUE(mesh.report().intersections_checked);
    bool built = true;
    const std::shared_ptr<const TriangleBvh> tree = mesh.bvh(&built);
    EXPECT_FALSE(built);
    expect_same_tree(*tree, build_triangle_bvh(mesh));
}

TEST(MeshBvh, ConcurrentFirstCallsBuildOnce) {
    const PreparedMesh mesh = prepare_mesh(make_icosphere(4), without_intersection_check());
    std::atomic<int> builds{0};
    std::vector<std::shared_ptr<const TriangleBvh>> seen(4);
    std::vector<std::thread> threads;
    for (size_t i = 0; i < seen.size(); ++i)
        threads.emplace_back([&, i] {
            bool built = false;
            seen[i] = mesh.bvh(&built);
            if (built) ++builds;
        });
    for (std::thread& t : threads) t.join();
    EXPECT_EQ(builds.load(), 1);
    for (const auto& s : seen) EXPECT_EQ(s, seen.front());
}

TEST(MeshBvh, SamplersAndCallsShareTheMeshTree) {
    const PreparedMesh mesh = prepare_mesh(make_torus(1.0, 0.3, 24, 12), without_intersection_check());
    const Lattice lattice = fit_lattice(LatticeType::CC, {10, 11, 12}, mesh.bounds(), 0.1);
    const SampledField a = make_cpu_bvh_sampler(quiet(SignMode::Winding))->bind(share(mesh))->sample(lattice);
    EXPECT_TRUE(built_by_bind(a));
    const SampledField b = make_cpu_bvh_sampler(quiet(SignMode::Winding))->bind(share(mesh))->sample(lattice);  // another sampler, bound again
    EXPECT_FALSE(built_by_bind(b));
    expect_same_field(a, b);
    // The provenance's build time is the tree's own, whichever call built it.
    EXPECT_EQ(a.sampler.details.at("bvh").at("build_seconds"), b.sampler.details.at("bvh").at("build_seconds"));
    EXPECT_EQ(b.sampler.details.at("bvh").at("build_seconds").get<double>(), mesh.bvh()->stats.seconds);
}

/// A bound sampler shares its mesh's ownership: the caller may drop its own pointer, and the
/// fields stay those of a fresh binding bit for bit. Binding no mesh is refused.
TEST(MeshBvh, ABoundSamplerOwnsItsMesh) {
    auto mesh = std::make_shared<const PreparedMesh>(prepare_mesh(make_torus(1.0, 0.3, 24, 12), without_intersection_check()));
    const Lattice lattice = fit_lattice(LatticeType::CC, {9, 10, 11}, mesh->bounds(), 0.1);
    const std::weak_ptr<const PreparedMesh> watch = mesh;
    for (SignMode sign : {SignMode::Winding, SignMode::Pseudonormal}) {
        const auto bound = make_cpu_bvh_sampler(quiet(sign))->bind(mesh);
        const SampledField expected = bound->sample(lattice);
        mesh.reset();
        EXPECT_FALSE(watch.expired());
        expect_same_field(bound->sample(lattice), expected);
        mesh = bound->shared_mesh();
    }
    EXPECT_THROW(make_cpu_bvh_sampler(quiet(SignMode::Auto))->bind(nullptr), std::invalid_argument);
    EXPECT_THROW(make_cpu_brute_force_sampler(quiet(SignMode::Auto))->bind(nullptr), std::invalid_argument);
}

/// A mesh made where another was, from the same input (same name, content hash, triangle
/// count and bounds: all a cache keyed by mesh identity compared), but prepared otherwise:
/// inward, or flipped outward. A sampler that saw the first must not reuse its tree or its
/// winding sign (whose view points into the first mesh's freed buffers) for the second.
TEST(MeshBvh, AMeshAtAFreedMeshsAddressGetsItsOwnTree) {
    TriangleMesh inward = make_icosphere(2);
    for (Int3& t : inward.triangles) std::swap(t.y, t.z);
    MeshPreparationOptions keep_inward = without_intersection_check(), flip = without_intersection_check();
    keep_inward.orient_outward = false;
    const PreparedMesh fresh = prepare_mesh(inward, flip);
    ASSERT_TRUE(fresh.report().flipped);
    const Lattice lattice = fit_lattice(LatticeType::CC, {9, 9, 9}, fresh.bounds(), 0.2);

    for (SignMode sign : {SignMode::Winding, SignMode::Pseudonormal}) {
        SCOPED_TRACE(sign_mode_name(sign));
        const SampledField expected = make_cpu_bvh_sampler(quiet(sign))->bind(share(fresh))->sample(lattice);
        const SampledField expected_brute = make_cpu_brute_force_sampler(quiet(sign))->bind(share(fresh))->sample(lattice);
        auto bvh_sampler = make_cpu_bvh_sampler(quiet(sign));
        auto brute_sampler = make_cpu_brute_force_sampler(quiet(sign));

        alignas(PreparedMesh) unsigned char storage[sizeof(PreparedMesh)];
        PreparedMesh* first = new (storage) PreparedMesh(prepare_mesh(inward, keep_inward));
        ASSERT_FALSE(first->report().flipped);
        const SampledField before = bvh_sampler->bind(share(first))->sample(lattice);
        brute_sampler->bind(share(first))->sample(lattice);
        first->~PreparedMesh();
        PreparedMesh* second = new (storage) PreparedMesh(prepare_mesh(inward, flip));
        ASSERT_EQ(static_cast<void*>(second), static_cast<void*>(first));
        ASSERT_EQ(second->content_sha256(), fresh.content_sha256());

        const SampledField after = bvh_sampler->bind(share(second))->sample(lattice);
        EXPECT_TRUE(built_by_bind(after));  // the second mesh's own tree
        expect_same_field(after, expected);
        expect_same_field(brute_sampler->bind(share(second))->sample(lattice), expected_brute);
        if (sign == SignMode::Winding) {
            // The inward mesh's winding number is -1 inside: the centre is outside there.
            const size_t centre = size_t(lattice.num_points() / 2);
            EXPECT_GT(before.distance[centre], 0);
            EXPECT_LT(after.distance[centre], 0);
        }
        second->~PreparedMesh();
    }
}

}  // namespace
}  // namespace sdf
