// Sign "auto" on CAD-like models (tests/test_util/cad_models.h: closed solids whose planar
// faces are fans and strips over collinear points, at scales 1e-3 .. 1e3, offsets up to 1e4,
// axis-aligned and rotated): the report finds no self-intersection, so the mesh is
// sign-reliable with no warning, `auto` keeps the pseudonormal sign without a word on
// stderr, and that sign is right at the centre of every cell of the solid's grid (inside
// for occupied cells, outside for empty ones and those around the grid). The three answers
// (report, sign_reliable, auto) come from one rule: a mesh that breaks it gets all three.
#include <gtest/gtest.h>

#include <iostream>
#include <sstream>

#include "core/mesh/prepared_mesh.h"
#include "core/sampling/sampler_sign.h"
#include "cpu_reference/bvh/bvh_cpu.h"
#include "cpu_reference/sampling/brute_force_cpu.h"
#include "tests/test_util/cad_models.h"
#include "tests/test_util/shared_mesh.h"

namespace sdf {
namespace {

template <typename F>
std::string captured_cerr(F f) {
    std::ostringstream text;
    std::streambuf* old = std::cerr.rdbuf(text.rdbuf());
    try {
        f();
    } catch (...) {
        std::cerr.rdbuf(old);
        throw;
    }
    std::cerr.rdbuf(old);
    return text.str();
}

SamplerOptions auto_sign() {
    SamplerOptions o;
    o.precision = Precision::Double;
    o.progress = false;
    o.sign = SignMode::Auto;
    return o;
}

TEST(CadSign, AutoKeepsThePseudonormalSignWithoutAWarning) {
    int meshes = 0;
    for (const test::CadSolid& solid : test::cad_solids()) {
        std::vector<Vec3d> inside_grid, outside_grid;
        test::cad_cell_centres(solid, inside_grid, outside_grid);
        for (const test::CadPlacement& place : test::cad_placements()) {
            const PreparedMesh mesh = prepare_mesh(test::cad_mesh(solid, place));
            const MeshReport& r = mesh.report();
            ASSERT_TRUE(r.intersections_checked);
            EXPECT_EQ(r.self_intersecting_pairs, 0) << mesh.source();
            EXPECT_TRUE(r.sign_reliable()) << mesh.source() << ": " << r.sign_unreliable_reason();
            EXPECT_FALSE(r.flipped) << mesh.source();
            EXPECT_TRUE(mesh.warnings().empty()) << mesh.source() << ": " << mesh.warnings().front();

            SamplerSign sign(SignMode::Auto);
            EXPECT_EQ(captured_cerr([&] { sign.prepare(mesh); }), "") << mesh.source();
            EXPECT_EQ(sign.choice().mode, SignMode::Pseudonormal) << mesh.source() << ": " << sign.choice().reason;

            std::vector<Vec3d> points;
            for (const Vec3d& g : inside_grid) points.push_back(place.apply(g));
            for (const Vec3d& g : outside_grid) points.push_back(place.apply(g));
            std::vector<PointSample> bvh, brute;
            EXPECT_EQ(captured_cerr([&] { bvh = make_cpu_bvh_sampler(auto_sign())->bind(share(mesh))->query(points); }), "");
            brute = make_cpu_brute_force_sampler(auto_sign())->bind(share(mesh))->query(points);
            for (size_t i = 0; i < points.size(); ++i) {
                const bool inside = i < inside_grid.size();
                ASSERT_EQ(bvh[i].distance < 0, inside) << mesh.source() << " point " << i;
                ASSERT_EQ(brute[i].distance < 0, inside) << mesh.source() << " point " << i;
            }
            ++meshes;
        }
    }
    EXPECT_EQ(meshes, 5 * 14);
}

TEST(CadSign, ReportSignReliableAndAutoFollowOneRule) {
    // A CAD box with a second one through it: two shells that overlap. Every way of asking
    // says the pseudonormal sign is not to be trusted, for the same reason.
    const test::CadSolid box = test::cad_solids().front();
    const test::CadPlacement place = test::cad_placements().front();
    TriangleMesh both = test::cad_mesh(box, place);
    test::CadPlacement moved = place;
    moved.offset = place.apply({17, 11, 5});
    const TriangleMesh other = test::cad_mesh(box, moved);
    const int first = int(both.vertices.size());
    both.vertices.insert(both.vertices.end(), other.vertices.begin(), other.vertices.end());
    for (const Int3& t : other.triangles) both.triangles.push_back({t.x + first, t.y + first, t.z + first});
    const PreparedMesh mesh = prepare_mesh(both);
    EXPECT_EQ(mesh.report().overlapping_shells, 1);
    EXPECT_FALSE(mesh.report().sign_reliable());
    EXPECT_EQ(mesh.report().sign_unreliable_reason(), "the mesh has 2 shells");
    bool warned = false;
    for (const std::string& w : mesh.warnings()) warned = warned || w.find("overlapping shells") != std::string::npos;
    EXPECT_TRUE(warned);
    SamplerSign sign(SignMode::Auto);
    const std::string log = captured_cerr([&] { sign.prepare(mesh); });
    EXPECT_EQ(sign.choice().mode, SignMode::Winding);
    EXPECT_NE(log.find("the mesh has 2 shells"), std::string::npos) << log;

    MeshPreparationOptions unchecked;
    unchecked.detect_intersections = false;
    const PreparedMesh single = prepare_mesh(test::cad_mesh(box, place), unchecked);
    EXPECT_FALSE(single.report().sign_reliable());
    EXPECT_EQ(single.report().sign_unreliable_reason(), "self-intersections were not checked");
}

}  // namespace
}  // namespace sdf
