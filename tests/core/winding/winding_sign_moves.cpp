// Where the certified winding sign differs from the uncertified fast sign it replaces (the
// side of 1/2 of the fast winding number, beta 2, order 2, over the host SAH tree): every
// moved point of a CC lattice fitted to each mesh, listed with its exact w (long double
// brute force, exact_winding_long.h), and checked to be on its exact side. Also prints how
// the certified ladder decided the points and what it cost beside the fast sign.
//   winding_sign_moves [resolution] [mesh files...]   (default: 32, the test meshes and
//   bunny-open.obj and dragon-legacy.obj when SDF_DATA_PATH has them)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/lattice/lattice_fitting.h"
#include "core/mesh/load_mesh.h"
#include "core/mesh/shapes/procedural_shapes.h"
#include "core/parallel/parallel_for.h"
#include "core/winding/winding_sign.h"
#include "tests/core/winding/exact_winding_long.h"
#include "tests/cpu_reference/bvh/bvh_test_meshes.h"

namespace {

using namespace sdf;

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Returns the number of moved points that are NOT on their exact side (0: all good).
int check_mesh(const PreparedMesh& mesh, int resolution) {
    const Lattice lattice = fit_lattice(LatticeType::CC, {resolution, resolution, resolution}, mesh.bounds(), 0.1);
    std::vector<Vec3d> pts;
    for (int k = 0; k < resolution; ++k)
        for (int j = 0; j < resolution; ++j)
            for (int i = 0; i < resolution; ++i) pts.push_back(lattice.position_of_coords({2 * i, 2 * j, 2 * k}));
    const int64_t n = int64_t(pts.size());
    WindingSignOptions o;  // the samplers' (SamplerSign::winding_options()), or the environment's for measurements
    if (const char* e = std::getenv("SDF_WINDING_BETA")) o.accuracy.beta = std::atof(e);
    if (const char* e = std::getenv("SDF_WINDING_REFINE_FACTOR")) o.certification.refine_factor = std::atof(e);
    if (const char* e = std::getenv("SDF_WINDING_REFINEMENTS")) o.certification.refinements = std::atoi(e);
    const WindingSign sign(mesh, o);
    std::vector<uint8_t> fast(static_cast<size_t>(n)), certified(static_cast<size_t>(n)), stage(static_cast<size_t>(n));
    auto t0 = std::chrono::steady_clock::now();
    parallel_for(n, 256, 0, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) fast[size_t(i)] = fast_winding_number(sign.view(), pts[size_t(i)], WindingAccuracy<double>{}).value > 0.5;
    });
    const double fast_s = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    parallel_for(n, 256, 0, [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
            const WindingSide s = sign.side(pts[size_t(i)]);
            certified[size_t(i)] = s.inside;
            stage[size_t(i)] = uint8_t(s.stage);
        }
    });
    const double certified_s = seconds_since(t0);
    WindingSignCounts c;
    for (const uint8_t s : stage) c.add(WindingStage(s));
    std::printf("%s (%d triangles), CC %d^3 = %lld points: certified sign: fast %lld, refined %lld, direct %lld, ties %lld; "
                "%.3f s against %.3f s for the fast sign\n",
                mesh.name().c_str(), int(mesh.triangles().size()), resolution, (long long)n, (long long)c.fast,
                (long long)c.refined, (long long)c.direct, (long long)c.ties, certified_s, fast_s);
    int moved = 0, wrong = 0;
    for (int64_t i = 0; i < n; ++i) {
        if (fast[size_t(i)] == certified[size_t(i)]) continue;
        ++moved;
        const Vec3d& p = pts[size_t(i)];
        const long double w = exact_winding_long(mesh, p);
        const bool tie = stage[size_t(i)] == uint8_t(WindingStage::Tie);
        const bool right = tie || (w > 0.5L) == bool(certified[size_t(i)]);
        wrong += !right;
        std::printf("  moved: point %lld (%.17g, %.17g, %.17g): exact w = %.15Lf, fast %s -> certified %s%s%s\n",
                    (long long)i, p.x, p.y, p.z, w, fast[size_t(i)] ? "inside" : "outside",
                    certified[size_t(i)] ? "inside" : "outside", tie ? " (tie)" : "", right ? "" : "  NOT THE EXACT SIDE");
    }
    std::printf("  %d of %lld points moved, %d not on their exact side\n", moved, (long long)n, wrong);
    return wrong;
}

}  // namespace

int main(int argc, char** argv) {
    const int resolution = argc > 1 ? std::atoi(argv[1]) : 32;
    std::vector<PreparedMesh> meshes;
    if (argc > 2) {
        for (int a = 2; a < argc; ++a) meshes.push_back(prepare_mesh(load_mesh_file(argv[a])));
    } else {
        meshes.push_back(test::open_bowl());
        for (const char* file : {"bunny-open.obj", "dragon-legacy.obj"}) {
            const std::string path = test::find_data_file(file);
            if (!path.empty()) meshes.push_back(prepare_mesh(load_mesh_file(path)));
        }
    }
    int wrong = 0;
    for (const PreparedMesh& m : meshes) wrong += check_mesh(m, resolution);
    return wrong == 0 ? 0 : 1;
}
